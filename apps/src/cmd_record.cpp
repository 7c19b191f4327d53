// tomorig record: the recorder half of a split rig. Pulls FrameSets from the lossless stream
// (tomorig replay, or an acquisition process) and writes them with rig::Recorder, live (HDF5
// SWMR), so the file can be inspected while it grows and survives a crash. It connects by
// default; the sender binds. The sender's session start gives the file the rig config, pixel
// pitch and truth a `tomorig run` file has, and its end-of-acquisition message ends the
// recording (docs/wire-protocol.md, "Session messages").
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <zmq.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/console.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/recorder.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_session.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/receive_memory.h"

namespace tomorig::app {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;

// A recorder stops by itself after this long without a set (issue 23: a record after a replay
// that had ended waited for ever). A rig triggers at 1 Hz or faster, so a minute without a set
// means the acquisition has stopped; until the first set, the minute also covers the start of
// the sender. --idle-timeout 0 waits for ever (e.g. for a run started by hand later).
constexpr double kDefaultIdleTimeoutSeconds = 60.0;

struct RecordArgs {
  std::string from = "tcp://127.0.0.1:5555";
  bool bind = false;
  bool allow_remote = false;
  std::string token;
  std::optional<std::uint64_t> sets;
  std::string compression = "none";
  double idle_timeout_s = kDefaultIdleTimeoutSeconds;  // 0: wait for ever
  JsonOutput json;
  rig::RecorderOptions recorder;  // out, overwrite and disk_reserve_mb bound directly
};

// How often receive() returns to the loop when nothing arrives: bounds how late an idle
// timeout is noticed. Ctrl-C does not wait for it (the signal interrupts the receive).
constexpr std::chrono::milliseconds kReceivePoll{250};
// Refusals are counted always but printed only this often, so a misconfigured sender cannot
// flood the terminal.
constexpr std::uint64_t kPrintedRefusals = 10;

// "record: 12 sets  41.9 MB/s to disk  0 lost sets  0 refused  0 rejected" on a StatusLine:
// redrawn on a terminal, a plain line every few seconds into a log.
class RecordStatus {
 public:
  RecordStatus() : last_(Clock::now()) {}

  void update(const rig::RecorderReport& c, std::uint64_t rejected, const stream::ReceiverStats& r,
              bool final = false) {
    if (!final && !line_.due()) return;
    const auto now = Clock::now();
    const double dt = duration<double>(now - last_).count();
    const double mbps = dt > 0 ? static_cast<double>(c.bytes - last_bytes_) / dt / 1e6 : 0.0;
    // ZeroMQ does not expose its queue, so the status shows what the recorder can count.
    const std::string text = fmt::format("record: {} sets  {:.1f} MB/s to disk  {} lost sets  {} refused  {} rejected",
                                         c.written, mbps, r.sets_missing, c.refused, rejected);
    if (final) line_.finish(text);
    else line_.update(text);
    last_ = now;
    last_bytes_ = c.bytes;
  }
  // Ends a line rewritten in place, so another message starts on a fresh line.
  void break_line() { line_.break_line(); }

 private:
  StatusLine line_;
  Clock::time_point last_;
  std::uint64_t last_bytes_ = 0;
};

void record(const RecordArgs& args) {
  if (args.sets && *args.sets < 1) throw bad_input("--sets 0 is invalid: record at least one set (or omit --sets)");
  if (!(args.idle_timeout_s >= 0.0))
    throw bad_input(fmt::format("--idle-timeout {:g} is invalid: give seconds >= 0 (0: wait for ever)",
                                args.idle_timeout_s));
  rig::RecorderOptions options = args.recorder;
  options.compression = rig::parse_compression_option(args.compression);
  rig::prepare_output(options);

  // Received parts reuse freed memory instead of fresh pages (the receiving CPU cost per GB
  // drops by about half on loopback TCP); must precede the ZeroMQ context.
  stream::keep_receive_buffers();
  rig::StopSignalGuard stop;
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {args.from, args.bind, args.allow_remote};
  socket.endpoint.token = args.token;
  socket.timeout = kReceivePoll;
  stream::FrameReceiver receiver(context, socket);
  fmt::print(stderr, "record: {} {}, writing {}\n", args.bind ? "receiving on" : "receiving from", receiver.endpoint(),
             options.out.string());
  std::fflush(stderr);

  // The session file opens when the session start announces every camera's size, or else
  // with the first set that can define them (an older sender announces nothing).
  rig::StreamSession session;
  std::optional<rig::Recorder> recorder;
  // Opens the session for `cameras`, or says why it cannot (why_not_recordable): then nothing
  // is created, and the sets that would need it are counted as refused.
  auto open_recorder = [&](std::vector<storage::SessionCamera> cameras, std::string& why) {
    why = rig::why_not_recordable(cameras, options);
    if (!why.empty()) return false;
    storage::SessionInfo info = session.file_info(std::move(cameras), receiver.endpoint());
    rig::RecorderOptions o = options;
    o.cameras = std::move(info.cameras);
    o.rig_config_toml = std::move(info.rig_config_toml);
    o.software_version = std::move(info.software_version);
    o.created_utc = std::move(info.created_utc);
    if (session.announced()) o.truth = session.announced()->truth;
    recorder.emplace(std::move(o));
    return true;
  };

  RecordStatus status;
  std::uint64_t received_sets = 0;  // frame sets of the recorded session that arrived (written or refused)
  std::uint64_t rejected = 0;       // messages the decoder refused
  std::uint64_t refused_before_start = 0;
  auto print_refusal = [](std::uint64_t count, const char* what, std::uint64_t index, const std::string& why) {
    if (count <= kPrintedRefusals) fmt::print(stderr, "record: {} {}: {}\n", what, index, why);
  };
  auto report = [&] {
    rig::RecorderReport r = recorder ? recorder->report() : rig::RecorderReport{};
    r.refused += refused_before_start;
    return r;
  };
  auto update = [&](bool final) { status.update(report(), rejected, receiver.stats(), final); };
  std::string stopped_by;
  std::string new_session;  // set when another session started while this one was recorded
  auto last_arrival = Clock::now();
  while (!args.sets || report().written < *args.sets) {
    if (stop.stop_requested()) {
      stopped_by = stop.signal_name();
      break;
    }
    std::optional<stream::StreamMessage> message;
    try {
      message = receiver.receive_message();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;  // a signal: the loop head decides
      throw runtime_error(fmt::format("receiving from {} failed: {}", receiver.endpoint(), e.what()));
    } catch (const Error& e) {
      print_refusal(++rejected, "rejected message", receiver.stats().rejected_messages, e.what());
      continue;
    }
    if (!message) {
      if (args.idle_timeout_s > 0 && duration<double>(Clock::now() - last_arrival).count() >= args.idle_timeout_s) {
        stopped_by = fmt::format("no set for {:g} s (--idle-timeout)", args.idle_timeout_s);
        break;
      }
      update(false);
      continue;
    }
    last_arrival = Clock::now();

    if (auto* start = std::get_if<stream::SessionStart>(&*message)) {
      const std::uint64_t id = start->session_id;
      const auto outcome = session.on_start(std::move(*start), recorder.has_value());
      if (outcome == rig::StreamSession::StartOutcome::conflict) {
        new_session = fmt::format("{:016x}", id);
        break;
      }
      if (outcome == rig::StreamSession::StartOutcome::adopted) {
        const stream::SessionStart& s = *session.announced();
        status.break_line();
        fmt::print(stderr, "record: session {:016x} from tomorig {}: {} cameras, rig config {} bytes{}\n", id,
                   s.info.software_version.empty() ? "(unknown version)" : s.info.software_version,
                   s.info.cameras.size(), s.info.rig_config_toml.size(), s.truth ? ", with truth" : "");
        std::string why;
        if (auto known = session.cameras_known_in_advance(); known && !open_recorder(std::move(*known), why))
          fmt::print(stderr, "record: session {:016x} cannot be recorded ({}); its sets will be refused\n", id, why);
      }
      continue;
    }
    if (auto* truth = std::get_if<stream::SetTruth>(&*message)) {
      session.on_truth(std::move(*truth));
      continue;
    }
    if (auto* end = std::get_if<stream::SessionEnd>(&*message)) {
      if (session.on_end(*end)) break;
      continue;  // the end of a session this recorder never saw start
    }

    const FrameSet& set = std::get<FrameSet>(*message);
    ++received_sets;
    std::string why;
    if (!recorder) {
      auto learned = session.cameras_from_first_set(set, why);
      if (!learned || !open_recorder(std::move(*learned), why)) {
        print_refusal(++refused_before_start, "refused set", set.set_index, "it cannot start the session: " + why);
        continue;
      }
    }
    const std::optional<storage::TruthSet> truth = session.take_truth(set.trigger_index);
    rig::Recorder::Outcome outcome;
    try {
      outcome = recorder->add(set, truth ? &*truth : nullptr, &why);
    } catch (const Error&) {
      update(true);
      throw;
    }
    if (outcome == rig::Recorder::Outcome::refused) {
      print_refusal(report().refused, "refused set", set.set_index, why);
      continue;
    }
    if (outcome == rig::Recorder::Outcome::stopped) {  // disk full: close the session with every set before it
      update(true);
      fmt::print("{}\n", recorder->finish().brief());
      throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", why,
                                      options.out.string(), recorder->report().written));
    }
    if (verbosity() == Verbosity::verbose) {
      status.break_line();
      spdlog::debug("record: wrote set {} (trigger {}) as set {}", set.set_index, set.trigger_index,
                    recorder->report().written - 1);
    }
    update(false);
  }
  update(true);

  const stream::ReceiverStats received = receiver.stats();
  if (!recorder || !recorder->started())
    throw runtime_error(fmt::format("no usable frame set arrived from {} ({}); nothing was recorded. Is the sender "
                                    "running, and does one side bind and the other connect?",
                                    receiver.endpoint(),
                                    session.ended() ? "the sender ended its session without a set"
                                    : stopped_by.empty() ? "stopped"
                                                         : stopped_by));
  recorder->finish();
  const rig::RecorderReport done = report();
  const auto& end = session.ended();
  std::string ending;
  if (end)
    ending = fmt::format("; the sender ended the session: {}{}", to_string(end->outcome),
                         end->reason.empty() ? "" : " (" + end->reason + ")");
  else if (!stopped_by.empty())
    ending = "; stopped: " + stopped_by;
  const auto refused_peers = stream::refused_connections();
  if (!args.json.to_stdout()) {
    fmt::print("{}; {} lost sets, {} refused sets, {} rejected messages, {} session messages{}\n", done.brief(),
               received.sets_missing, done.refused, rejected, received.session_messages, ending);
    if (refused_peers.count > 0)
      fmt::print("{} connections refused for a wrong token (last from {})\n", refused_peers.count,
                 refused_peers.last_peer);
    fmt::print("next: tomorig inspect {}\n", done.out.string());
  }
  nlohmann::json j = json_summary("record");
  j[json_key::kOut] = done.out.string();
  j[json_key::kSets] = done.written;
  j["bytes"] = done.bytes;
  j["lost_sets"] = received.sets_missing;
  j["refused_sets"] = done.refused;
  j["rejected_messages"] = rejected;
  j["refused_connections"] = refused_peers.count;
  j["sender_outcome"] = end ? std::string(to_string(end->outcome)) : std::string();
  j["stopped_by"] = stopped_by;
  emit_json(args.json, j);
  if (end && end->sets_sent > received_sets)
    throw runtime_error(fmt::format("{} of the {} sets the sender sent never arrived; {} is complete with the {} that "
                                    "were recorded",
                                    end->sets_sent - received_sets, end->sets_sent, done.out.string(), done.written));
  if (!new_session.empty())
    throw runtime_error(fmt::format("another session ({}) started on {} before the end of the one being recorded; {} "
                                    "is complete with {} sets. Record the next session with another -o",
                                    new_session, receiver.endpoint(), done.out.string(), done.written));
}

}  // namespace

void add_record_command(CLI::App& root) {
  auto args = std::make_shared<RecordArgs>();
  CLI::App* cmd = root.add_subcommand(
      "record", "Record frame sets from the lossless stream into a session file (connects; the sender binds)");
  cmd->add_option("--from", args->from, "Stream endpoint of the sender (tomorig replay / acquire)")
      ->capture_default_str();
  cmd->add_flag("--bind", args->bind, "Bind --from instead of connecting (then the sender connects)");
  cmd->add_flag("--allow-remote", args->allow_remote, "Allow --bind on a non-loopback address (needs --token)");
  cmd->add_option("--token", args->token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("-o,--out", args->recorder.out, "Session file to write (.h5)")->required();
  cmd->add_option("--sets", args->sets, "Stop after this many sets (default: at the sender's end of acquisition, Ctrl-C or --idle-timeout)");
  cmd->add_option("--compression", args->compression, "Frame compression: none | bitshuffle-lz4")
      ->capture_default_str();
  cmd->add_option("--idle-timeout", args->idle_timeout_s,
                  "Stop when no set arrived for this many seconds (counted from the start until the first set); 0: "
                  "wait for ever")
      ->capture_default_str();
  cmd->add_flag("--overwrite", args->recorder.overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", args->recorder.disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_option("--max-set-mb", args->recorder.max_set_mb,
                  "Refuse a first set larger than this many MB of pixels (it would size the session)")
      ->capture_default_str();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { record(*args); });
}

}  // namespace tomorig::app
