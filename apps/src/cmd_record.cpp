// tomorig record: the recorder half of a split rig. Pulls FrameSets from the lossless stream
// (tomorig replay, or an acquisition process) and writes them with rig::Recorder, live (HDF5
// SWMR), so the file can be inspected while it grows and survives a crash. It connects by
// default; the sender binds.
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/recorder.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/stream/frame_receiver.h"

namespace tomorig::app {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;

struct RecordArgs {
  std::string from = "tcp://127.0.0.1:5555";
  bool bind = false;
  bool allow_remote = false;
  std::optional<std::uint64_t> sets;
  std::string compression = "none";
  std::optional<double> idle_timeout_s;
  bool verbose = false;
  rig::RecorderOptions recorder;  // out, overwrite and disk_reserve_mb bound directly
};

// How often receive() returns to the loop when nothing arrives: bounds how late an idle
// timeout is noticed. Ctrl-C does not wait for it (the signal interrupts the receive).
constexpr std::chrono::milliseconds kReceivePoll{250};
// Refusals are counted always but printed only this often, so a misconfigured sender cannot
// flood the terminal.
constexpr std::uint64_t kPrintedRefusals = 10;

// "record: 12 sets  41.9 MB/s to disk  0 lost sets  0 refused  0 rejected", rewritten in place
// on a terminal, at most 4 times a second (once a second otherwise).
class RecordStatus {
 public:
  RecordStatus() : tty_(isatty(STDERR_FILENO) == 1), last_(Clock::now()) {}

  void update(const rig::RecorderReport& c, std::uint64_t rejected, const stream::ReceiverStats& r,
              bool final = false) {
    const auto now = Clock::now();
    const double dt = duration<double>(now - last_).count();
    if (!final && dt < (tty_ ? 0.25 : 1.0)) return;
    const double mbps = dt > 0 ? static_cast<double>(c.bytes - last_bytes_) / dt / 1e6 : 0.0;
    // ZeroMQ does not expose its queue, so the status shows what the recorder can count.
    fmt::print(stderr, "{}record: {} sets  {:.1f} MB/s to disk  {} lost sets  {} refused  {} rejected{}",
               tty_ ? "\r" : "", c.written, mbps, r.sets_missing, c.refused, rejected, tty_ && !final ? "   " : "\n");
    last_ = now;
    last_bytes_ = c.bytes;
  }

 private:
  bool tty_;
  Clock::time_point last_;
  std::uint64_t last_bytes_ = 0;
};

void record(const RecordArgs& args) {
  if (args.sets && *args.sets < 1) throw bad_input("--sets 0 is invalid: record at least one set (or omit --sets)");
  if (args.idle_timeout_s && !(*args.idle_timeout_s > 0.0))
    throw bad_input(fmt::format("--idle-timeout {:g} is invalid: it must be > 0 seconds", *args.idle_timeout_s));
  rig::RecorderOptions options = args.recorder;
  options.compression = rig::parse_compression_option(args.compression);
  rig::prepare_output(options);

  rig::StopSignalGuard stop;
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {args.from, args.bind, args.allow_remote};
  socket.timeout = kReceivePoll;
  stream::FrameReceiver receiver(context, socket);
  fmt::print(stderr, "record: {} {}, writing {}\n", args.bind ? "receiving on" : "receiving from", receiver.endpoint(),
             options.out.string());
  std::fflush(stderr);
  options.rig_config_toml = fmt::format(
      "# recorded by 'tomorig record' from {}; the stream does not carry the rig configuration\n", receiver.endpoint());
  rig::Recorder recorder(options);  // the first set that can tells the cameras

  RecordStatus status;
  std::uint64_t rejected = 0;  // messages the decoder refused
  auto print_refusal = [](std::uint64_t count, const char* what, std::uint64_t index, const std::string& why) {
    if (count <= kPrintedRefusals) fmt::print(stderr, "record: {} {}: {}\n", what, index, why);
  };
  auto update = [&](bool final) { status.update(recorder.report(), rejected, receiver.stats(), final); };
  std::string stopped_by;
  auto last_arrival = Clock::now();
  while (!args.sets || recorder.report().written < *args.sets) {
    if (stop.stop_requested()) {
      stopped_by = stop.signal_name();
      break;
    }
    std::optional<FrameSet> set;
    try {
      set = receiver.receive();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;  // a signal: the loop head decides
      throw runtime_error(fmt::format("receiving from {} failed: {}", receiver.endpoint(), e.what()));
    } catch (const Error& e) {
      print_refusal(++rejected, "rejected message", receiver.stats().rejected_messages, e.what());
      continue;
    }
    if (!set) {
      if (args.idle_timeout_s && duration<double>(Clock::now() - last_arrival).count() >= *args.idle_timeout_s) {
        stopped_by = fmt::format("no set for {:g} s (--idle-timeout)", *args.idle_timeout_s);
        break;
      }
      update(false);
      continue;
    }
    last_arrival = Clock::now();
    std::string why;
    rig::Recorder::Outcome outcome;
    try {
      outcome = recorder.add(*set, nullptr, &why);
    } catch (const Error&) {
      update(true);
      throw;
    }
    if (outcome == rig::Recorder::Outcome::refused) {
      print_refusal(recorder.report().refused, "refused set", set->set_index, why);
      continue;
    }
    if (outcome == rig::Recorder::Outcome::stopped) {  // disk full: close the session with every set before it
      update(true);
      fmt::print("{}\n", recorder.finish().brief());
      throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", why,
                                      options.out.string(), recorder.report().written));
    }
    if (args.verbose)
      fmt::print(stderr, "record: wrote set {} (trigger {}) as set {}\n", set->set_index, set->trigger_index,
                 recorder.report().written - 1);
    update(false);
  }
  update(true);

  const stream::ReceiverStats received = receiver.stats();
  if (!recorder.started())
    throw runtime_error(fmt::format("no usable frame set arrived from {} ({}); nothing was recorded. Is the sender "
                                    "running, and does one side bind and the other connect?",
                                    receiver.endpoint(), stopped_by.empty() ? "stopped" : stopped_by));
  const rig::RecorderReport& report = recorder.finish();
  fmt::print("{}; {} lost sets, {} refused sets, {} rejected messages{}\n", report.brief(), received.sets_missing,
             report.refused, rejected, stopped_by.empty() ? "" : "; stopped: " + stopped_by);
  fmt::print("next: tomorig inspect {}\n", report.out.string());
}

}  // namespace

void add_record_command(CLI::App& root) {
  auto args = std::make_shared<RecordArgs>();
  CLI::App* cmd = root.add_subcommand(
      "record", "Record frame sets from the lossless stream into a session file (connects; the sender binds)");
  cmd->add_option("--from", args->from, "Stream endpoint of the sender (tomorig replay / acquire)")
      ->capture_default_str();
  cmd->add_flag("--bind", args->bind, "Bind --from instead of connecting (then the sender connects)");
  cmd->add_flag("--allow-remote", args->allow_remote, "Allow --bind on a non-loopback address");
  cmd->add_option("-o,--out", args->recorder.out, "Session file to write (.h5)")->required();
  cmd->add_option("--sets", args->sets, "Stop after this many sets (default: until Ctrl-C or --idle-timeout)");
  cmd->add_option("--compression", args->compression, "Frame compression: none | bitshuffle-lz4")
      ->capture_default_str();
  cmd->add_option("--idle-timeout", args->idle_timeout_s, "Stop when no set arrived for this many seconds");
  cmd->add_flag("--overwrite", args->recorder.overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", args->recorder.disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", args->verbose, "Print a line for every set written");
  cmd->callback([args] { record(*args); });
}

}  // namespace tomorig::app
