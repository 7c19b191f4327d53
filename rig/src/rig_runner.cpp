#include "tomorig/rig/rig_runner.h"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <exception>
#include <filesystem>
#include <optional>
#include <thread>
#include <utility>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/rig/record_layout.h"
#include "tomorig/rig/rig_session_info.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/rig/rig_status.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr const char* kInprocEndpoint = "inproc://tomorig-run";

// Moves assembled sets from the rig into the lossless stream on its own thread, so the
// recorder (the calling thread) and the acquisition loop never wait on each other directly:
// ZeroMQ's queue between them is the back-pressure. Destruction stops and joins it.
class StreamPump {
 public:
  StreamPump(RigAcquisition& rig, stream::FrameSender& sender)
      : thread_([this, &rig, &sender] { pump(rig, sender); }) {}
  ~StreamPump() {
    abort_ = true;
    if (thread_.joinable()) thread_.join();
  }
  StreamPump(const StreamPump&) = delete;
  StreamPump& operator=(const StreamPump&) = delete;

  bool done() const { return done_; }
  void abort() { abort_ = true; }
  // Rethrows what ended the pump early, if anything (call after done()).
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  void pump(RigAcquisition& rig, stream::FrameSender& sender) {
    try {
      while (!abort_) {
        std::optional<FrameSet> set = rig.pop(100ms);
        if (!set) {
          if (rig.done()) break;
          continue;
        }
        while (!sender.send(*set))  // no room within the timeout: the recorder is busy
          if (abort_) break;
      }
    } catch (...) {
      error_ = std::current_exception();
    }
    done_ = true;
  }

  std::atomic<bool> abort_{false};
  std::atomic<bool> done_{false};
  std::exception_ptr error_;
  std::thread thread_;
};

stream::SocketOptions inproc_pull() {
  stream::SocketOptions pull;
  pull.endpoint = {kInprocEndpoint, /*bind=*/true, false};
  pull.timeout = 250ms;
  return pull;
}

stream::SocketOptions inproc_push() {
  stream::SocketOptions push = inproc_pull();
  push.endpoint.bind = false;
  return push;
}

}  // namespace

std::string human_bytes(std::uintmax_t bytes) {
  if (bytes >= 1024 * 1024) return fmt::format("{:.1f} MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  if (bytes >= 1024) return fmt::format("{:.1f} KiB", static_cast<double>(bytes) / 1024.0);
  return fmt::format("{} B", bytes);
}

std::string RigRunReport::brief() const {
  return fmt::format("wrote {}: {} set{} x {} cameras, {} in {:.2f} s; {} lost frames, {} incomplete sets",
                     recording.out.string(), recording.written, recording.written == 1 ? "" : "s", cameras,
                     human_bytes(file_bytes), seconds, frames_lost, incomplete_sets);
}

struct RigRunner::Impl {
  Impl(const config::RigConfig& rig, RigRunOptions opt)
      : options(std::move(opt)),
        rig_name(rig.name),
        rig_toml(rig.source_text),
        stages(pipeline::make_chain(all_stages(), options.stages)),
        acquisition((prepare_output(options.recorder), rig), with_truth(options.acquisition)),
        recorder(recorder_options(rig, options.recorder, acquisition)),
        losses(acquisition.camera_ids()),
        receiver(context, inproc_pull()),
        sender(context, inproc_push()),
        status(options.status_label, context, options.status_endpoint) {}

  static RigAcquisitionOptions with_truth(RigAcquisitionOptions o) {
    o.keep_truth = true;
    return o;
  }
  static RecorderOptions recorder_options(const config::RigConfig& rig, RecorderOptions o,
                                          const RigAcquisition& acquisition) {
    // What `acquire` announces to a split rig's recorder, so the two files cannot differ.
    storage::SessionInfo info = rig_session_info(rig, acquisition);
    o.cameras = std::move(info.cameras);
    o.rig_config_toml = std::move(info.rig_config_toml);
    o.software_version = std::move(info.software_version);
    o.truth = acquisition.session_truth();
    return o;
  }

  RigRunReport run(const StopCondition& should_stop);
  void refresh(bool final);
  void notice(const std::string& text) {
    status.break_line();
    if (options.notice) options.notice(text);
  }

  RigRunOptions options;
  std::string rig_name, rig_toml;
  pipeline::StageChain stages;  // configured first: a bad stage setting fails before the rig is armed
  bool stages_begun = false;
  RigAcquisition acquisition;  // built and armed first: a bad rig fails before the file exists
  Recorder recorder;
  LossTally losses;
  zmq::context_t context{1};
  stream::FrameReceiver receiver;
  stream::FrameSender sender;
  StatusReporter status;
  StatusFigures figures;
};

void RigRunner::Impl::refresh(bool final) {
  const RigProgress progress = acquisition.progress();
  // The receiver may count a set the sender's counter does not show yet: never below zero.
  const std::uint64_t received = receiver.stats().sets_received;
  figures.queue_depth = progress.queued_sets + sets_in_flight(sender.stats().sets_sent, received);
  take_progress(figures, progress);
  const std::filesystem::path out = options.recorder.out;
  std::error_code ec;
  const auto space = std::filesystem::space(out.has_parent_path() ? out.parent_path() : std::filesystem::path("."), ec);
  if (!ec) figures.disk_free_bytes = space.available;
  status.update(figures, losses, final);
}

RigRunReport RigRunner::Impl::run(const StopCondition& should_stop) {
  const auto started = Clock::now();
  RigRunReport report;
  acquisition.start();
  StreamPump pump(acquisition, sender);
  figures.total = options.acquisition.sets;
  for (;;) {
    for (const auto& text : acquisition.take_notices()) notice(text);
    if (!report.stopped && should_stop && should_stop(recorder.report())) {
      report.stopped = true;
      figures.state = "stopping";
      acquisition.request_stop();
    }
    std::optional<FrameSet> set;
    try {
      set = receiver.receive();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;  // a signal: the loop head decides
      throw runtime_error(fmt::format("the in-process stream failed: {}", e.what()));
    }
    if (!set) {
      if (pump.done() && receiver.stats().sets_received >= sender.stats().sets_sent) break;
      refresh(false);
      continue;
    }
    losses.add(*set);
    const std::optional<storage::TruthSet> truth = acquisition.take_truth(set->trigger_index);
    const Recorder::Outcome outcome = recorder.add(*set, truth ? &*truth : nullptr);
    if (outcome == Recorder::Outcome::stopped) break;
    if (outcome == Recorder::Outcome::refused) continue;  // counted in the losses; a later set starts the session
    if (!stages.empty()) {
      if (!stages_begun) {  // the first set written fixed the cameras
        pipeline::SessionDescription recording = pipeline::describe_recording(
            fmt::format("live rig '{}'", rig_name), recorder.cameras(), rig_toml, acquisition.session_truth());
        recording.store_quicklook = [this](const storage::QuickLookRecord& r) { recorder.add_quicklook(r); };
        stages.begin(recording);
        stages_begun = true;
      }
      // Stages see the set under its index in the session (a refused set has none).
      set->set_index = recorder.report().written - 1;
      stages.push(*set);
    }
    figures.sets = recorder.report().written;
    figures.bytes = recorder.report().bytes;
    refresh(false);
  }
  pump.abort();
  acquisition.request_stop();
  report.failure = acquisition.failure();
  figures.state = recorder.report().disk_full.empty() && report.failure.empty() ? "stopped" : "failed";
  refresh(true);
  pump.rethrow();

  if (!recorder.started())
    throw runtime_error(fmt::format("no complete frame set arrived, so nothing was recorded{}",
                                    report.failure.empty() ? "" : ": " + report.failure));
  // Stages end first: what they still store with the session (the quick-look of the last
  // sets) goes in before the file is closed.
  if (stages_begun) report.stages = stages.end();
  report.recording = recorder.finish();
  report.cameras = recorder.cameras().size();
  report.frames_lost = losses.frames_lost();
  report.incomplete_sets = losses.incomplete_sets();
  std::error_code ec;
  report.file_bytes = std::filesystem::file_size(report.recording.out, ec);
  if (ec) report.file_bytes = 0;
  report.seconds = std::chrono::duration<double>(Clock::now() - started).count();
  return report;
}

RigRunner::RigRunner(const config::RigConfig& rig, RigRunOptions options)
    : impl_(std::make_unique<Impl>(rig, std::move(options))) {}

RigRunner::~RigRunner() = default;

std::string RigRunner::status_endpoint() const { return impl_->status.endpoint(); }

RigRunReport RigRunner::run(const StopCondition& should_stop) { return impl_->run(should_stop); }

}  // namespace tomorig::rig
