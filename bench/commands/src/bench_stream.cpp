// tomorig bench stream: thesis-scale FrameSets over the lossless ZeroMQ path (loopback TCP,
// as between `acquire` and `record`; ipc, the same-host alternative; inproc, as inside `run`),
// next to a memcpy of the same bytes measured in the same run (issues 6 and 13,
// docs/performance.md). Sender and receiver have a ZeroMQ context each over tcp and ipc, as
// two processes would; CPU time is the whole process's, both sides included.
#include <sys/resource.h>

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
#include "tomorig/stream/receive_memory.h"

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
  int warmup_sets = 8;
  bool plain_malloc = false;
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

// Page faults the process took so far (receive buffers faulted in show up here).
long minor_page_faults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

std::string bench_address(const std::string& transport) {
  if (transport == "tcp") return "tcp://127.0.0.1:*";
  if (transport == "ipc") return "ipc://*";  // ZeroMQ picks a fresh socket file
  return "inproc://tomorig-bench";
}

nlohmann::json stream_run(const FrameSet& set, const std::string& transport, const BenchStreamArgs& args) {
  zmq::context_t send_context(args.io_threads);
  zmq::context_t own_receive_context(transport == "inproc" ? 0 : args.io_threads);
  zmq::context_t& receive_context = transport == "inproc" ? send_context : own_receive_context;
  stream::SocketOptions out;
  out.endpoint.address = bench_address(transport);
  out.timeout = std::chrono::seconds(20);
  out.high_water_mark = args.high_water_mark;
  stream::FrameSender sender(send_context, out);
  stream::SocketOptions in = out;
  in.endpoint = {sender.endpoint(), false, false};
  stream::FrameReceiver receiver(receive_context, in);

  // The first sets fault in the receive buffers and grow the socket buffers; the figures are
  // for the steady state after them.
  const int total = args.warmup_sets + args.sets;
  bool send_failed = false;
  std::thread producer([&] {
    for (int i = 0; i < total; ++i) {
      FrameSet s = set;  // shares the pixel buffers: the sender sends them zero-copy
      s.set_index = static_cast<std::uint64_t>(i);
      if (!sender.send(s)) {
        send_failed = true;
        return;
      }
    }
  });
  int received = 0;
  for (; received < args.warmup_sets; ++received)
    if (!receiver.receive()) break;
  const double cpu0 = process_cpu_seconds();
  const long faults0 = minor_page_faults();
  const auto start = Clock::now();
  for (; received < total; ++received)
    if (!receiver.receive()) break;
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  const double cpu = process_cpu_seconds() - cpu0;
  const long faults = minor_page_faults() - faults0;
  producer.join();
  if (send_failed || received < total)
    throw runtime_error(fmt::format("bench stream over {}: only {} of {} sets arrived", transport, received, total));
  const double bytes = static_cast<double>(set_bytes(set)) * args.sets;
  return {{"transport", transport},
          {"sets", args.sets},
          {"seconds", seconds},
          {"mb_per_s", bytes / seconds / 1e6},
          {"sets_per_s", args.sets / seconds},
          {"cpu_seconds", cpu},
          {"gb_per_cpu_second", cpu > 0 ? bytes / cpu / 1e9 : 0.0},
          {"cpu_seconds_per_gb", bytes > 0 ? cpu / (bytes / 1e9) : 0.0},
          {"page_faults_per_gb", bytes > 0 ? static_cast<double>(faults) / (bytes / 1e9) : 0.0},
          {"sets_missing", receiver.stats().sets_missing},
          {"blocked_sends", sender.stats().blocked_sends}};
}

void run(const BenchStreamArgs& args) {
  if (args.sets < 1 || args.cameras < 1 || args.side < 16 || args.warmup_sets < 0)
    throw bad_input("bench stream needs --sets >= 1, --cameras >= 1, --side >= 16 and --warmup >= 0");
  for (const std::string& t : args.transports)
    if (t != "tcp" && t != "ipc" && t != "inproc")
      throw bad_input(fmt::format("--transports: '{}' is not tcp, ipc or inproc", t));
  // As `tomorig record` does: received parts reuse freed memory instead of fresh pages.
  const bool kept = !args.plain_malloc && stream::keep_receive_buffers();
  fmt::print(stderr, "bench stream: {} sets of {} cameras x 2 x {}^2 Mono16 ({:.0f} MiB per set)\n", args.sets,
             args.cameras, args.side, args.cameras * 2.0 * args.side * args.side * 2 / (1 << 20));
  const FrameSet set = synthetic_particle_set(args.cameras, args.side, 1);
  const double memcpy_rate = memcpy_mb_per_s(set, 8);
  nlohmann::json results = nlohmann::json::array();
  for (const std::string& t : args.transports) {
    nlohmann::json r = stream_run(set, t, args);
    r["ratio_to_memcpy"] = r["mb_per_s"].get<double>() / memcpy_rate;
    fmt::print(stderr, "  {:6} {:8.0f} MB/s  {:6.1f} sets/s  ({:.3f} of memcpy)  {:.3f} CPU-s per GB  {:.0f} page faults per GB\n",
               t, r["mb_per_s"].get<double>(), r["sets_per_s"].get<double>(), r["ratio_to_memcpy"].get<double>(),
               r["cpu_seconds_per_gb"].get<double>(), r["page_faults_per_gb"].get<double>());
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
              {"warmup_sets", args.warmup_sets},
              {"keep_receive_buffers", kept},
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
  cmd->add_option("--transports", args->transports, "tcp, ipc, inproc")->delimiter(',');
  cmd->add_option("--warmup", args->warmup_sets, "Sets sent before the measurement starts")->capture_default_str();
  cmd->add_flag("--plain-malloc", args->plain_malloc,
                "Leave glibc's allocator settings alone (to measure what keep_receive_buffers() saves)");
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
