// tomorig bench stream: thesis-scale FrameSets over the lossless ZeroMQ path (loopback TCP,
// as between `acquire` and `record`, and inproc, as inside `run`), next to a memcpy of the
// same bytes measured in the same run (issue 6, docs/performance.md).
#include <chrono>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <zmq.hpp>

#include "bench_common.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::bench {
namespace {
using Clock = std::chrono::steady_clock;

struct BenchStreamArgs {
  int sets = 48;
  int cameras = 4;
  int side = 2048;
  int io_threads = 1;
  int high_water_mark = 4;
  std::vector<std::string> transports{"tcp", "inproc"};
  std::string json_out;
};

double memcpy_mb_per_s(const FrameSet& set, int repeats) {
  std::vector<std::vector<std::byte>> out;
  for (const auto& cam : set.cameras)
    for (const Frame* f : {&cam.a, &cam.b}) out.emplace_back(f->image.size_bytes(), std::byte{1});
  const auto start = Clock::now();
  for (int r = 0; r < repeats; ++r) {
    std::size_t k = 0;
    for (const auto& cam : set.cameras)
      for (const Frame* f : {&cam.a, &cam.b}) {
        std::memcpy(out[k].data(), f->image.data(), out[k].size());
        ++k;
      }
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return static_cast<double>(set_bytes(set)) * repeats / seconds / 1e6;
}

nlohmann::json stream_run(const FrameSet& set, const std::string& transport, const BenchStreamArgs& args) {
  zmq::context_t context(args.io_threads);
  stream::SocketOptions out;
  out.endpoint.address = transport == "tcp" ? "tcp://127.0.0.1:*" : "inproc://tomorig-bench";
  out.timeout = std::chrono::seconds(20);
  out.high_water_mark = args.high_water_mark;
  stream::FrameSender sender(context, out);
  stream::SocketOptions in = out;
  in.endpoint = {sender.endpoint(), false, false};
  stream::FrameReceiver receiver(context, in);

  const double cpu0 = process_cpu_seconds();
  const auto start = Clock::now();
  bool send_failed = false;
  std::thread producer([&] {
    for (int i = 0; i < args.sets; ++i) {
      FrameSet s = set;  // shares the pixel buffers: the sender sends them zero-copy
      s.set_index = static_cast<std::uint64_t>(i);
      if (!sender.send(s)) {
        send_failed = true;
        return;
      }
    }
  });
  int received = 0;
  for (; received < args.sets; ++received)
    if (!receiver.receive()) break;
  producer.join();
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = process_cpu_seconds() - cpu0;
  if (send_failed || received < args.sets)
    throw runtime_error(fmt::format("bench stream over {}: only {} of {} sets arrived", transport, received, args.sets));
  const double bytes = static_cast<double>(set_bytes(set)) * received;
  return {{"transport", transport},
          {"sets", received},
          {"seconds", seconds},
          {"mb_per_s", bytes / seconds / 1e6},
          {"sets_per_s", received / seconds},
          {"cpu_seconds", cpu},
          {"gb_per_cpu_second", cpu > 0 ? bytes / cpu / 1e9 : 0.0},
          {"sets_missing", receiver.stats().sets_missing},
          {"blocked_sends", sender.stats().blocked_sends}};
}

void run(const BenchStreamArgs& args) {
  if (args.sets < 1 || args.cameras < 1 || args.side < 16)
    throw bad_input("bench stream needs --sets >= 1, --cameras >= 1 and --side >= 16");
  fmt::print(stderr, "bench stream: {} sets of {} cameras x 2 x {}^2 Mono16 ({:.0f} MiB per set)\n", args.sets,
             args.cameras, args.side, args.cameras * 2.0 * args.side * args.side * 2 / (1 << 20));
  const FrameSet set = synthetic_particle_set(args.cameras, args.side, 1);
  const double memcpy_rate = memcpy_mb_per_s(set, 8);
  nlohmann::json results = nlohmann::json::array();
  for (const std::string& t : args.transports) {
    if (t != "tcp" && t != "inproc") throw bad_input(fmt::format("--transports: '{}' is not tcp or inproc", t));
    nlohmann::json r = stream_run(set, t, args);
    r["ratio_to_memcpy"] = r["mb_per_s"].get<double>() / memcpy_rate;
    fmt::print(stderr, "  {:6} {:8.0f} MB/s  {:6.1f} sets/s  ({:.3f} of memcpy)\n", t, r["mb_per_s"].get<double>(),
               r["sets_per_s"].get<double>(), r["ratio_to_memcpy"].get<double>());
    results.push_back(std::move(r));
  }
  // The thesis rig: 4 sCMOS x 2560 x 2160 x 2 exposures x 2 bytes at 25 Hz.
  const double target = 4.0 * 2560 * 2160 * 2 * 2 * 25 / 1e6;
  write_json({{"bench", "stream"},
              {"machine", machine_json()},
              {"set_bytes", set_bytes(set)},
              {"memcpy_mb_per_s", memcpy_rate},
              {"target_mb_per_s", target},
              {"io_threads", args.io_threads},
              {"high_water_mark", args.high_water_mark},
              {"results", results}},
             args.json_out);
}

}  // namespace

void add_bench_stream_command(CLI::App& bench) {
  auto args = std::make_shared<BenchStreamArgs>();
  CLI::App* cmd = bench.add_subcommand("stream", "FrameSets over the lossless ZeroMQ path vs memcpy of the same bytes");
  cmd->add_option("--sets", args->sets, "Sets to send")->capture_default_str();
  cmd->add_option("--cameras", args->cameras, "Cameras per set")->capture_default_str();
  cmd->add_option("--side", args->side, "Frame width and height, pixels (Mono16)")->capture_default_str();
  cmd->add_option("--io-threads", args->io_threads, "ZeroMQ I/O threads")->capture_default_str();
  cmd->add_option("--hwm", args->high_water_mark, "Sets queued before the sender waits")->capture_default_str();
  cmd->add_option("--transports", args->transports, "tcp, inproc")->delimiter(',');
  cmd->add_option("--json", args->json_out, "Write the JSON here ('-' or empty: stdout)");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
