// tomorig record: the recorder half of a split rig. Pulls FrameSets from the lossless stream
// (tomorig replay, or an acquisition process) and writes them live (HDF5 SWMR) into a session
// file, so the file can be inspected while it grows and survives a crash. It connects by
// default; the sender binds. The sender's session start gives the file the rig config, pixel
// pitch and truth a `tomorig run` file has, and its end-of-acquisition message ends the
// recording (docs/wire-protocol.md, "Session messages").
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "tomorig/rig/record_layout.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_session.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/receive_memory.h"

namespace tomorig::app {

using rig::StreamSession;
using rig::StopSignalGuard;
using rig::set_matches_cameras;
using rig::pixel_bytes;

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;

struct RecordOptions {
  std::string from = "tcp://127.0.0.1:5555";
  bool bind = false;
  bool allow_remote = false;
  std::string out;
  std::optional<std::uint64_t> sets;
  std::string compression = "none";
  std::optional<double> idle_timeout_s;
  bool overwrite = false;
  bool verbose = false;
  double disk_reserve_mb = 64.0;
};

// How often receive() returns to the loop when nothing arrives: bounds how late an idle
// timeout is noticed. Ctrl-C does not wait for it (the signal interrupts the receive).
constexpr std::chrono::milliseconds kReceivePoll{250};
// Refusals are counted always but printed only this often, so a misconfigured sender cannot
// flood the terminal.
constexpr std::uint64_t kPrintedRefusals = 10;

double seconds_since(Clock::time_point t) { return duration<double>(Clock::now() - t).count(); }

struct RecordCounts {
  std::uint64_t written = 0;
  std::uint64_t received = 0;  // frame sets of the recorded session that arrived (written or refused)
  std::uint64_t bytes_written = 0;
  std::uint64_t refused = 0;   // sets whose cameras or sizes differ from the session's
  std::uint64_t rejected = 0;  // messages the decoder refused
};

class RecordStatus {
 public:
  RecordStatus() : tty_(isatty(STDERR_FILENO) == 1), last_(Clock::now()) {}

  void update(const RecordCounts& c, const stream::ReceiverStats& r, bool final = false) {
    const auto now = Clock::now();
    const double dt = duration<double>(now - last_).count();
    if (!final && dt < (tty_ ? 0.25 : 1.0)) return;
    const double mbps = dt > 0 ? static_cast<double>(c.bytes_written - last_bytes_) / dt / 1e6 : 0.0;
    // ZeroMQ does not expose its queue, so the status shows what the recorder can count.
    fmt::print(stderr, "{}record: {} sets  {:.1f} MB/s to disk  {} lost sets  {} refused  {} rejected{}",
               tty_ ? "\r" : "", c.written, mbps, r.sets_missing, c.refused, c.rejected, tty_ && !final ? "   " : "\n");
    last_ = now;
    last_bytes_ = c.bytes_written;
    line_open_ = tty_ && !final;
  }
  // Ends a line rewritten in place, so another message starts on a fresh line.
  void break_line() {
    if (line_open_) fmt::print(stderr, "\n");
    line_open_ = false;
  }

 private:
  bool tty_;
  bool line_open_ = false;
  Clock::time_point last_;
  std::uint64_t last_bytes_ = 0;
};

void check_output(const RecordOptions& opt, const std::filesystem::path& out) {
  if (std::filesystem::exists(out) && !opt.overwrite)
    throw bad_input(fmt::format("{} exists; choose another -o or pass --overwrite", out.string()));
  if (out.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(out.parent_path(), ec);
    if (ec)
      throw bad_input(fmt::format("cannot create the output folder {}: {}; choose another -o",
                                  out.parent_path().string(), ec.message()));
  }
}

void record(const RecordOptions& opt) {
  if (!(opt.disk_reserve_mb >= 0.0))
    throw bad_input(fmt::format("--disk-reserve-mb {:g} is invalid: it must be >= 0", opt.disk_reserve_mb));
  if (opt.sets && *opt.sets < 1) throw bad_input("--sets 0 is invalid: record at least one set (or omit --sets)");
  if (opt.idle_timeout_s && !(*opt.idle_timeout_s > 0.0))
    throw bad_input(fmt::format("--idle-timeout {:g} is invalid: it must be > 0 seconds", *opt.idle_timeout_s));
  const auto compression = storage::parse_compression(opt.compression);
  if (!compression)
    throw bad_input(fmt::format("--compression {} is not supported (none, bitshuffle-lz4)", opt.compression));
  const std::filesystem::path out(opt.out);
  check_output(opt, out);

  // Received parts reuse freed memory instead of fresh pages (the receiving CPU cost per GB
  // drops by about half on loopback TCP); must precede the ZeroMQ context.
  stream::keep_receive_buffers();
  StopSignalGuard stop;
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {opt.from, opt.bind, opt.allow_remote};
  socket.timeout = kReceivePoll;
  stream::FrameReceiver receiver(context, socket);
  fmt::print(stderr, "record: {} {}, writing {}\n", opt.bind ? "receiving on" : "receiving from", receiver.endpoint(),
             out.string());
  std::fflush(stderr);

  storage::SessionWriterOptions writer_options;
  writer_options.compression = *compression;
  writer_options.overwrite = opt.overwrite;
  writer_options.live = true;
  writer_options.disk_reserve_bytes = static_cast<std::uint64_t>(opt.disk_reserve_mb * 1e6);
  std::unique_ptr<storage::SessionWriter> writer;
  std::vector<storage::SessionCamera> cameras;
  StreamSession session;
  auto open_writer = [&](std::vector<storage::SessionCamera> session_cameras) {
    cameras = session_cameras;
    writer = std::make_unique<storage::SessionWriter>(
        out, session.file_info(std::move(session_cameras), receiver.endpoint()), writer_options);
    if (session.announced() && session.announced()->truth) writer->write_truth(*session.announced()->truth);
  };

  RecordCounts counts;
  RecordStatus status;
  auto refuse = [](std::uint64_t& counter, const char* what, std::uint64_t index, const std::string& why) {
    if (++counter <= kPrintedRefusals) fmt::print(stderr, "record: {} {}: {}\n", what, index, why);
  };
  std::string stopped_by;
  std::string new_session;  // set when another session started while this one was recorded
  auto last_arrival = Clock::now();
  while (!opt.sets || counts.written < *opt.sets) {
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
      refuse(counts.rejected, "rejected message", receiver.stats().rejected_messages, e.what());
      continue;
    }
    if (!message) {
      if (opt.idle_timeout_s && seconds_since(last_arrival) >= *opt.idle_timeout_s) {
        stopped_by = fmt::format("no set for {:g} s (--idle-timeout)", *opt.idle_timeout_s);
        break;
      }
      status.update(counts, receiver.stats());
      continue;
    }
    last_arrival = Clock::now();

    if (auto* start = std::get_if<stream::SessionStart>(&*message)) {
      const std::uint64_t id = start->session_id;
      const auto outcome = session.on_start(std::move(*start), writer != nullptr);
      if (outcome == StreamSession::StartOutcome::conflict) {
        new_session = fmt::format("{:016x}", id);
        break;
      }
      if (outcome == StreamSession::StartOutcome::adopted) {
        const stream::SessionStart& s = *session.announced();
        status.break_line();
        fmt::print(stderr, "record: session {:016x} from tomorig {}: {} cameras, rig config {} bytes{}\n", id,
                   s.info.software_version.empty() ? "(unknown version)" : s.info.software_version,
                   s.info.cameras.size(), s.info.rig_config_toml.size(), s.truth ? ", with truth" : "");
        if (auto known = session.cameras_known_in_advance()) open_writer(std::move(*known));
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

    FrameSet& set = std::get<FrameSet>(*message);
    ++counts.received;
    std::string why;
    if (!writer) {
      auto learned = session.cameras_from_first_set(set, why);
      if (!learned) {
        refuse(counts.refused, "refused set", set.set_index, "it cannot start the session: " + why);
        continue;
      }
      open_writer(std::move(*learned));
    }
    if (!set_matches_cameras(set, cameras, why)) {
      refuse(counts.refused, "refused set", set.set_index, why);
      continue;
    }
    try {
      writer->append(set);
      if (auto truth = session.take_truth(set.trigger_index)) writer->write_truth_set(counts.written, *truth);
    } catch (const storage::DiskFullError& e) {
      // Nothing of this set was written: close the session cleanly with every set before it.
      status.update(counts, receiver.stats(), /*final=*/true);
      writer->finish();
      fmt::print("recorded {} sets ({:.1f} MB of pixels) to {}\n", counts.written,
                 static_cast<double>(counts.bytes_written) / 1e6, out.string());
      throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", e.what(), out.string(),
                                      counts.written));
    } catch (const Error& e) {
      // The live writer keeps "<name>.partial" with every set written so far.
      status.update(counts, receiver.stats(), /*final=*/true);
      throw runtime_error(fmt::format("recording stopped after {} sets: {}; the sets written so far are in {}",
                                      counts.written, e.what(), writer->partial_path().string()));
    }
    ++counts.written;
    counts.bytes_written += pixel_bytes(set);
    if (opt.verbose)
      fmt::print(stderr, "record: wrote set {} (trigger {}) as set {}\n", set.set_index, set.trigger_index,
                 counts.written - 1);
    status.update(counts, receiver.stats());
  }
  status.update(counts, receiver.stats(), /*final=*/true);

  const stream::ReceiverStats received = receiver.stats();
  if (!writer)
    throw runtime_error(fmt::format("no usable frame set arrived from {} ({}); nothing was recorded. Is the sender "
                                    "running, and does one side bind and the other connect?",
                                    receiver.endpoint(),
                                    session.ended() ? "the sender ended its session without a set"
                                    : stopped_by.empty() ? "stopped"
                                                         : stopped_by));
  writer->finish();
  const auto& end = session.ended();
  std::string ending;
  if (end)
    ending = fmt::format("; the sender ended the session: {}{}", to_string(end->outcome),
                         end->reason.empty() ? "" : " (" + end->reason + ")");
  else if (!stopped_by.empty())
    ending = "; stopped: " + stopped_by;
  fmt::print("recorded {} sets ({:.1f} MB of pixels) to {}; {} lost sets, {} refused sets, {} rejected messages{}\n",
             counts.written, static_cast<double>(counts.bytes_written) / 1e6, out.string(), received.sets_missing,
             counts.refused, counts.rejected, ending);
  fmt::print("next: tomorig inspect {}\n", out.string());
  if (end && end->sets_sent > counts.received)
    throw runtime_error(fmt::format("{} of the {} sets the sender sent never arrived; {} is complete with the {} that "
                                    "were recorded",
                                    end->sets_sent - counts.received, end->sets_sent, out.string(), counts.written));
  if (!new_session.empty())
    throw runtime_error(fmt::format("another session ({}) started on {} before the end of the one being recorded; {} "
                                    "is complete with {} sets. Record the next session with another -o",
                                    new_session, receiver.endpoint(), out.string(), counts.written));
}

}  // namespace

void add_record_command(CLI::App& root) {
  auto opt = std::make_shared<RecordOptions>();
  CLI::App* cmd = root.add_subcommand(
      "record", "Record frame sets from the lossless stream into a session file (connects; the sender binds)");
  cmd->add_option("--from", opt->from, "Stream endpoint of the sender (tomorig replay / acquire)")
      ->capture_default_str();
  cmd->add_flag("--bind", opt->bind, "Bind --from instead of connecting (then the sender connects)");
  cmd->add_flag("--allow-remote", opt->allow_remote, "Allow --bind on a non-loopback address");
  cmd->add_option("-o,--out", opt->out, "Session file to write (.h5)")->required();
  cmd->add_option("--sets", opt->sets,
                  "Stop after this many sets (default: at the sender's end of acquisition, Ctrl-C or --idle-timeout)");
  cmd->add_option("--compression", opt->compression, "Frame compression: none | bitshuffle-lz4")
      ->capture_default_str();
  cmd->add_option("--idle-timeout", opt->idle_timeout_s, "Stop when no set arrived for this many seconds");
  cmd->add_flag("--overwrite", opt->overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", opt->disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_flag("-v,--verbose", opt->verbose, "Print a line for every set written");
  cmd->callback([opt] { record(*opt); });
}

}  // namespace tomorig::app
