#include "tomorig/rig/stream_acquisition.h"

#include <algorithm>
#include <chrono>
#include <optional>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/rig/record_layout.h"
#include "tomorig/rig/rig_session_info.h"
#include "tomorig/rig/rig_status.h"
#include "tomorig/rig/send_with_retry.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::duration_cast;

// The longest a send (or the wait for a recorder) blocks before the loop looks at Ctrl-C again.
constexpr std::chrono::milliseconds kSendSlice{50};
// The longest the loop waits for a set before it refreshes the status and looks at Ctrl-C.
constexpr std::chrono::milliseconds kPopWait{100};

}  // namespace

void StreamAcquisitionOptions::validate() const {
  if (!(timeout_s > 0.0) || !(wait_s > 0.0))
    throw bad_input(fmt::format("--timeout {:g} / --wait {:g} are invalid: both must be > 0 seconds", timeout_s, wait_s));
}

std::string StreamAcquisitionReport::brief() const {
  if (!announced)
    return fmt::format("no recorder took the session start; stopped by {} before acquiring",
                       stopped_by.empty() ? "a stop request" : stopped_by);
  return fmt::format("acquired and sent {} sets ({:.1f} MB) on {}; {} lost frames, {} incomplete sets{}", sets_sent,
                     static_cast<double>(bytes_sent) / 1e6, endpoint, frames_lost, incomplete_sets,
                     stopped_by.empty() ? "" : fmt::format(", stopped by {}", stopped_by));
}

struct StreamAcquisition::Impl {
  StreamAcquisitionOptions options;
  RigAcquisition rig_run;
  storage::SessionInfo info;

  Impl(const config::RigConfig& rig, StreamAcquisitionOptions o)
      : options((o.validate(), o.acquisition.keep_truth = true, std::move(o))),  // the recorder gets the truth
        rig_run(rig, options.acquisition),
        info(rig_session_info(rig, rig_run)) {}

  StreamAcquisitionReport run(const StreamAcquisitionHooks& hooks);
  // Waits for a recorder to connect and take the session start; false if a stop came first.
  bool announce(stream::FrameSender& sender, const stream::SessionStart& start, const StopSignalGuard* stop) const;
};

StreamAcquisition::StreamAcquisition(const config::RigConfig& rig, StreamAcquisitionOptions options)
    : impl_(std::make_unique<Impl>(rig, std::move(options))) {}
StreamAcquisition::~StreamAcquisition() = default;

const RigAcquisition& StreamAcquisition::acquisition() const { return impl_->rig_run; }
StreamAcquisitionReport StreamAcquisition::run(const StreamAcquisitionHooks& hooks) { return impl_->run(hooks); }

bool StreamAcquisition::Impl::announce(stream::FrameSender& sender, const stream::SessionStart& start,
                                       const StopSignalGuard* stop) const {
  // A connecting socket (connect) would queue the session start with nobody there, so the wait
  // is for a connected recorder first, then for it to take the session start; no set queues up
  // unrecorded meanwhile because the trigger has not started.
  const auto began = Clock::now();
  while (!sender.wait_for_receiver(kSendSlice)) {
    if (stop && stop->stop_requested()) return false;
    if (duration<double>(Clock::now() - began).count() >= options.wait_s)
      throw runtime_error(fmt::format("no recorder connected to {} within {:g} s (--wait): is 'tomorig record --{} {}' "
                                      "running?",
                                      sender.endpoint(), options.wait_s, options.connect ? "bind --from" : "from",
                                      sender.endpoint()));
  }
  return send_with_retry(sender, start, options.wait_s, stop) == SendOutcome::sent;
}

StreamAcquisitionReport StreamAcquisition::Impl::run(const StreamAcquisitionHooks& hooks) {
  const StopSignalGuard* stop = hooks.stop;
  const auto notice = [&](const std::string& text) {
    if (hooks.notice) hooks.notice(text);
  };
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {options.to, !options.connect, options.allow_remote};
  socket.endpoint.token = options.token;
  // Each send waits at most one slice, so Ctrl-C is seen within it even when the signal lands on
  // another thread than the one blocked in ZeroMQ; send_with_retry keeps trying for timeout_s
  // (or wait_s). Closing still waits one timeout_s for queued sets.
  socket.linger = duration_cast<std::chrono::milliseconds>(duration<double>(options.timeout_s));
  socket.timeout = std::min(kSendSlice, *socket.linger);
  auto sender = std::make_unique<stream::FrameSender>(context, socket);
  StreamAcquisitionReport report;
  report.endpoint = sender->endpoint();
  if (hooks.sending) hooks.sending(report.endpoint);
  StatusReporter status(options.status_label, context, options.status_endpoint);
  if (!status.endpoint().empty() && hooks.status_socket) hooks.status_socket(status.endpoint());

  LossTally losses(rig_run.camera_ids());
  StatusFigures figures;
  figures.total = options.acquisition.sets;
  figures.to_disk = false;
  auto refresh = [&](bool final) {
    const RigProgress progress = rig_run.progress();
    figures.queue_depth = progress.queued_sets;
    take_progress(figures, progress);
    status.update(figures, losses, final);
  };
  auto stopping = [&](const char* signal) {
    report.stopped_by = signal;
    figures.state = "stopping";
    rig_run.request_stop();
  };

  stream::SessionStart start;
  start.session_id = stream::new_session_id();
  start.info = info;
  start.truth = rig_run.session_truth();
  report.announced = announce(*sender, start, stop);
  if (!report.announced) {  // Ctrl-C while waiting: nothing acquired, nothing to close
    report.stopped_by = stop ? stop->signal_name() : "";
    return report;
  }

  rig_run.start();
  while (!rig_run.done()) {
    for (const auto& text : rig_run.take_notices()) {
      status.break_line();
      notice(text);
    }
    if (report.stopped_by.empty() && stop && stop->stop_requested()) stopping(stop->signal_name());
    std::optional<FrameSet> set = rig_run.pop(kPopWait);
    if (!set) {
      refresh(false);
      continue;
    }
    if (auto truth = rig_run.take_truth(set->trigger_index))
      send_with_retry(*sender, stream::SetTruth{start.session_id, set->trigger_index, std::move(*truth)},
                      options.timeout_s, nullptr);
    // Ctrl-C interrupts a wait for the recorder; the set in hand and those already acquired
    // still go out, each with the normal timeout.
    if (send_with_retry(*sender, *set, options.timeout_s, report.stopped_by.empty() ? stop : nullptr) ==
        SendOutcome::stopped) {
      stopping(stop->signal_name());
      send_with_retry(*sender, *set, options.timeout_s, nullptr);
    }
    losses.add(*set);
    ++figures.sets;
    figures.bytes += pixel_bytes(*set);
    if (hooks.sent) hooks.sent(*set);
    refresh(false);
  }
  for (const auto& text : rig_run.take_notices()) notice(text);
  rig_run.request_stop();
  report.failure = rig_run.failure();

  // The end of acquisition: the recorder closes its file when it has every set sent before.
  stream::SessionEnd end;
  end.session_id = start.session_id;
  end.sets_sent = sender->stats().sets_sent;
  if (!report.failure.empty()) {
    end.outcome = stream::SessionOutcome::failed;
    end.reason = report.failure;
  } else if (!report.stopped_by.empty()) {
    end.outcome = stream::SessionOutcome::stopped;
    end.reason = "stopped by " + report.stopped_by;
  }
  try {
    send_with_retry(*sender, end, options.timeout_s, nullptr);
  } catch (const Error& e) {
    if (report.stopped_by.empty()) throw;
    // Stopped by the operator, typically after the recorder: nobody is left to tell.
    notice(e.what());
  }

  // Hand every queued set to the transport: closing the sender waits (up to one timeout of
  // linger) until ZeroMQ has written them to the recorder.
  const stream::SenderStats sent = sender->stats();
  sender.reset();
  report.sets_sent = sent.sets_sent;
  report.bytes_sent = sent.bytes_sent;
  report.frames_lost = losses.frames_lost();
  report.incomplete_sets = losses.incomplete_sets();
  figures.state = report.failure.empty() ? "stopped" : "failed";
  refresh(true);
  return report;
}

}  // namespace tomorig::rig
