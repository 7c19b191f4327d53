#include "tomorig/rig/stream_recording.h"

#include <cerrno>
#include <chrono>
#include <variant>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_session.h"
#include "tomorig/stream/receive_memory.h"

#include "rate_status_line.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;

// How often receive() returns to the loop when nothing arrives: bounds how late an idle
// timeout is noticed. Ctrl-C does not wait for it (the signal interrupts the receive).
constexpr std::chrono::milliseconds kReceivePoll{250};
// Refusals are counted always but reported only this often, so a misconfigured sender cannot
// flood the terminal.
constexpr std::uint64_t kPrintedRefusals = 10;

// "record: 12 sets  41.9 MB/s to disk  0 lost sets  0 refused  0 rejected": redrawn on a
// terminal, a plain line every few seconds into a log.
class RecordStatus {
 public:
  explicit RecordStatus(bool enabled) : line_(enabled) {}

  void update(const RecorderReport& c, std::uint64_t rejected, const stream::ReceiverStats& r, bool final = false) {
    line_.update(c.written, c.bytes, final, [&](const RateStatusLine::Rates& rates) {
      // ZeroMQ does not expose its queue, so the status shows what the recorder can count.
      return fmt::format("record: {} sets  {:.1f} MB/s to disk  {} lost sets  {} refused  {} rejected", c.written,
                         rates.mb_per_second, r.sets_missing, c.refused, rejected);
    });
  }
  void break_line() { line_.break_line(); }

 private:
  RateStatusLine line_;
};

}  // namespace

std::string StreamRecordingReport::brief() const {
  std::string ending;
  if (sender_end)
    ending = fmt::format("; the sender ended the session: {}{}", to_string(sender_end->outcome),
                         sender_end->reason.empty() ? "" : " (" + sender_end->reason + ")");
  else if (!stopped_by.empty())
    ending = "; stopped: " + stopped_by;
  return fmt::format("{}; {} lost sets, {} refused sets, {} rejected messages, {} session messages{}", recording.brief(),
                     received.sets_missing, recording.refused, rejected, received.session_messages, ending);
}

std::string StreamRecordingReport::failure() const {
  if (sender_end && sender_end->sets_sent > received_sets)
    return fmt::format("{} of the {} sets the sender sent never arrived; {} is complete with the {} that were recorded",
                       sender_end->sets_sent - received_sets, sender_end->sets_sent, recording.out.string(),
                       recording.written);
  if (!new_session.empty())
    return fmt::format("another session ({}) started on {} before the end of the one being recorded; {} is complete "
                       "with {} sets. Record the next session with another -o",
                       new_session, endpoint, recording.out.string(), recording.written);
  return {};
}

StreamRecording::StreamRecording(StreamRecordingOptions options) : options_(std::move(options)) {
  if (options_.sets && *options_.sets < 1)
    throw bad_input("--sets 0 is invalid: record at least one set (or omit --sets)");
  if (!(options_.idle_timeout_s >= 0.0))
    throw bad_input(fmt::format("--idle-timeout {:g} is invalid: give seconds >= 0 (0: wait for ever)",
                                options_.idle_timeout_s));
  options_.recorder.compression = parse_compression_option(options_.compression);
  prepare_output(options_.recorder);
}

StreamRecordingReport StreamRecording::run(const StreamRecordingHooks& hooks) {
  const RecorderOptions& options = options_.recorder;
  const auto notice = [&](const std::string& text) {
    if (hooks.notice) hooks.notice(text);
  };
  // Received parts reuse freed memory instead of fresh pages (the receiving CPU cost per GB
  // drops by about half on loopback TCP); must precede the ZeroMQ context.
  stream::keep_receive_buffers();
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {options_.from, options_.bind, options_.allow_remote};
  socket.endpoint.token = options_.token;
  socket.timeout = kReceivePoll;
  stream::FrameReceiver receiver(context, socket);
  if (hooks.receiving) hooks.receiving(receiver.endpoint());

  // The session file opens when the session start announces every camera's size, or else
  // with the first set that can define them (an older sender announces nothing).
  StreamSession session;
  std::optional<Recorder> recorder;
  // Opens the session for `cameras`, or says why it cannot (why_not_recordable): then nothing
  // is created, and the sets that would need it are counted as refused.
  auto open_recorder = [&](std::vector<storage::SessionCamera> cameras, std::string& why) {
    why = why_not_recordable(cameras, options);
    if (!why.empty()) return false;
    storage::SessionInfo info = session.file_info(std::move(cameras), receiver.endpoint());
    RecorderOptions o = options;
    o.cameras = std::move(info.cameras);
    o.rig_config_toml = std::move(info.rig_config_toml);
    o.software_version = std::move(info.software_version);
    o.created_utc = std::move(info.created_utc);
    if (session.announced()) o.truth = session.announced()->truth;
    recorder.emplace(std::move(o));
    return true;
  };

  RecordStatus status(options_.status_line);
  StreamRecordingReport out;
  out.endpoint = receiver.endpoint();
  std::uint64_t refused_before_start = 0;
  auto refusal = [&](std::uint64_t count, const char* what, std::uint64_t index, const std::string& why) {
    if (count <= kPrintedRefusals) notice(fmt::format("{} {}: {}", what, index, why));
  };
  auto report = [&] {
    RecorderReport r = recorder ? recorder->report() : RecorderReport{};
    r.refused += refused_before_start;
    return r;
  };
  auto update = [&](bool final) { status.update(report(), out.rejected, receiver.stats(), final); };
  auto last_arrival = Clock::now();
  while (!options_.sets || report().written < *options_.sets) {
    if (hooks.stop && hooks.stop->stop_requested()) {
      out.stopped_by = hooks.stop->signal_name();
      break;
    }
    std::optional<stream::StreamMessage> message;
    try {
      message = receiver.receive_message();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;  // a signal: the loop head decides
      throw runtime_error(fmt::format("receiving from {} failed: {}", receiver.endpoint(), e.what()));
    } catch (const Error& e) {
      refusal(++out.rejected, "rejected message", receiver.stats().rejected_messages, e.what());
      continue;
    }
    if (!message) {
      if (options_.idle_timeout_s > 0 &&
          duration<double>(Clock::now() - last_arrival).count() >= options_.idle_timeout_s) {
        out.stopped_by = fmt::format("no set for {:g} s (--idle-timeout)", options_.idle_timeout_s);
        break;
      }
      update(false);
      continue;
    }
    last_arrival = Clock::now();

    if (auto* start = std::get_if<stream::SessionStart>(&*message)) {
      const std::uint64_t id = start->session_id;
      const auto outcome = session.on_start(std::move(*start), recorder.has_value());
      if (outcome == StreamSession::StartOutcome::conflict) {
        out.new_session = fmt::format("{:016x}", id);
        break;
      }
      if (outcome == StreamSession::StartOutcome::adopted) {
        const stream::SessionStart& s = *session.announced();
        status.break_line();
        notice(fmt::format("session {:016x} from tomorig {}: {} cameras, rig config {} bytes{}", id,
                           s.info.software_version.empty() ? "(unknown version)" : s.info.software_version,
                           s.info.cameras.size(), s.info.rig_config_toml.size(), s.truth ? ", with truth" : ""));
        std::string why;
        if (auto known = session.cameras_known_in_advance(); known && !open_recorder(std::move(*known), why))
          notice(fmt::format("session {:016x} cannot be recorded ({}); its sets will be refused", id, why));
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
    ++out.received_sets;
    std::string why;
    if (!recorder) {
      auto learned = session.cameras_from_first_set(set, why);
      if (!learned || !open_recorder(std::move(*learned), why)) {
        refusal(++refused_before_start, "refused set", set.set_index, "it cannot start the session: " + why);
        continue;
      }
    }
    const std::optional<storage::TruthSet> truth = session.take_truth(set.trigger_index);
    Recorder::Outcome outcome;
    try {
      outcome = recorder->add(set, truth ? &*truth : nullptr, &why);
    } catch (const Error&) {
      update(true);
      throw;
    }
    if (outcome == Recorder::Outcome::refused) {
      refusal(report().refused, "refused set", set.set_index, why);
      continue;
    }
    if (outcome == Recorder::Outcome::stopped) {  // disk full: close the session with every set before it
      update(true);
      const std::string brief = recorder->finish().brief();
      if (hooks.stopped_early) hooks.stopped_early(brief);
      throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", why, options.out.string(),
                                      recorder->report().written));
    }
    if (hooks.wrote) {
      status.break_line();
      hooks.wrote(set, recorder->report().written - 1);
    }
    update(false);
  }
  update(true);

  out.received = receiver.stats();
  if (!recorder || !recorder->started())
    throw runtime_error(fmt::format("no usable frame set arrived from {} ({}); nothing was recorded. Is the sender "
                                    "running, and does one side bind and the other connect?",
                                    receiver.endpoint(),
                                    session.ended()           ? "the sender ended its session without a set"
                                    : out.stopped_by.empty() ? "stopped"
                                                             : out.stopped_by));
  recorder->finish();
  out.recording = report();
  out.sender_end = session.ended();
  return out;
}

}  // namespace tomorig::rig
