// quicklook: issue 16's online processing as a stage. Per set it sees, per camera: the
// quick-look statistics of both frames and the Δt check; on its own thread, for the newest set
// it can keep up with: the preview volume and the drift monitor. Results go out on the preview
// PUB stream (JSON plus small images) and into the session file being recorded (/quicklook).
// It may skip sets to stay current; the sets it never saw and the sets the preview passed over
// are counted. Targets come from the rig file's [quicklook] tables (docs/quicklook.md).
//
//   --stage quicklook                                  statistics, preview, drift; stored, not published
//   --stage quicklook:publish=tcp://127.0.0.1:5557     and published (tomorig run --preview does this)
//   --stage quicklook:preview=off                      statistics and Δt check only
//   --stage quicklook:preview=ment,threads=2           MENT previews on two threads
//   --stage quicklook:nice=5,preview_nice=10           the threads' nice values (the defaults)
//   --stage quicklook:shadow=on                        the spray quick-look (shadow_look.h) in place of
//                                                      particle statistics; auto (default): on for a
//                                                      spray-thesis recording or a rig lit by LEDs only
//
// The recorder comes first: the stage's threads run at raised nice values (thread_priority.h),
// the statistics of every set above the preview volume, which skips sets to stay current.
#include <time.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include <fmt/format.h>
#include <zmq.hpp>

#include "preview_worker.h"
#include "quicklook_report.h"
#include "thread_priority.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/pipeline/stage.h"

namespace tomorig::pipeline {
namespace {

constexpr std::size_t kStatisticsMayLagSets = 5;

using namespace quicklook_stage;
using Clock = std::chrono::steady_clock;

// CPU time of the calling thread, s: what the quick-look costs, whatever else loads the machine.
double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

class QuickLookStage final : public Stage {
 public:
  void configure(const StageTable& table) override {
    publish_ = table.text("publish", publish_);
    allow_remote_ = table.flag("allow_remote", allow_remote_);
    store_ = table.flag("store", store_);
    preview_ = table.text("preview", preview_);
    if (preview_ != "on" && preview_ != "off" && preview_ != "mlos" && preview_ != "ment")
      throw bad_input(fmt::format("stage 'quicklook': preview = {} is not one of on, off, mlos, ment", preview_));
    if (table.has("threads")) threads_ = static_cast<int>(table.integer("threads", 0));
    thumbnail_px_ = static_cast<int>(table.integer("thumbnail_px", thumbnail_px_));
    if (thumbnail_px_ < 16 || thumbnail_px_ > 1024)
      throw bad_input(fmt::format("stage 'quicklook': thumbnail_px = {} is out of range: use 16 to 1024", thumbnail_px_));
    calib_ = table.text("calib", calib_);
    shadow_ = table.text("shadow", shadow_);
    if (shadow_ != "auto" && shadow_ != "on" && shadow_ != "off")
      throw bad_input(fmt::format("stage 'quicklook': shadow = {} is not one of auto, on, off", shadow_));
    for (auto [key, value] : {std::pair{"nice", &nice_}, std::pair{"preview_nice", &preview_nice_}}) {
      *value = static_cast<int>(table.integer(key, *value));
      if (*value < 0 || *value > 19)
        throw bad_input(fmt::format("stage 'quicklook': {} = {} is out of range: use 0 to 19", key, *value));
    }
    // Bound now, so a taken or forbidden address fails before the rig is armed.
    if (!publish_.empty() && publish_ != "none") {
      stream::SocketOptions options = stream::preview_socket_options(publish_);
      options.endpoint.allow_remote = allow_remote_;
      options.endpoint.allow_remote_option = "the stage key allow_remote=true (--stage quicklook:allow_remote=true)";
      publisher_ = std::make_unique<stream::PreviewPublisher>(context_, options);
    }
  }

  void begin(const SessionDescription& recording) override {
    QuickLookSettings settings = quicklook_settings(recording.rig_config());
    if (preview_ == "mlos" || preview_ == "ment") settings.preview.algorithm = preview_;
    if (threads_) settings.preview.threads = *threads_;
    settings.preview.validate();
    settings.store = store_;
    settings.thumbnail_px = thumbnail_px_;
    settings.nice = nice_;
    settings.preview_nice = preview_nice_;
    settings_ = settings;
    store_quicklook_ = store_ ? recording.store_quicklook : nullptr;

    shadow_mode_ = shadow_ == "on" || (shadow_ == "auto" && is_shadowgraphy(recording));
    for (const storage::SessionCamera& camera : recording.cameras) {
      quicklook::QuickLookOptions options = settings.statistics;
      options.bit_depth = bit_depth(camera.pixel_format);
      statistics_.emplace_back(options);
      dt_checks_.emplace_back(settings.dt_check);
      quicklook::ShadowLookOptions shadow = settings.shadow;
      shadow.bit_depth = options.bit_depth;
      shadow_looks_.emplace_back(shadow);
      results_.push_back({.id = camera.id, .shadow = shadow_mode_});
    }
    // The preview volume reconstructs particle light; shadow images would need inverting and
    // flat-fielding first (issue 20's processing presets), so shadow mode has no preview yet.
    if (preview_ != "off" && !shadow_mode_) start_preview(recording, settings);
  }

  // One camera's statistics and Δt check (or its shadow look), into results_[c]; every camera
  // has its own kernels, so two threads may measure two cameras at once.
  void measure_camera(std::size_t c, const CameraFrames& frames, double& background) {
    CameraResult& r = results_[c];
    r.measured = frames.a.present() && frames.b.present();
    r.missing = r.measured ? "" : frames.a.present() ? "frame B missing" : "frame A missing";
    if (!r.measured) return;
    // A frame these kernels cannot take (too small, float) is reported for its camera; it
    // does not stop the quick-look of the others.
    if (shadow_mode_) {
      try {
        shadow_looks_[c].analyse(frames.a.image, frames.b.image, r.shadow_look);
      } catch (const Error& e) {
        r.measured = false;
        r.missing = e.what();
      }
      return;
    }
    try {
      statistics_[c].analyse(frames.a.image, frames.b.image, r.statistics);
      background = r.statistics.a.background;
    } catch (const Error& e) {
      r.measured = false;
      r.missing = e.what();
      return;
    }
    try {
      dt_checks_[c].check(frames.a.image, frames.b.image, r.dt_check);
    } catch (const Error&) {
      r.dt_check = {};  // not measured: null figures, red
    }
  }

  void process(const FrameSet& set) override {
    const auto taken = Clock::now();
    // process() runs on the stage's own thread (StageRunner gives every stage that may skip
    // sets one, stage_chain.cpp), never on the recorder's, so this lowers the quick-look alone.
    if (!priority_lowered_) {
      priority_error_ = lower_this_thread_priority(settings_.nice);
      priority_lowered_ = true;
    }
    const double cpu_start = thread_cpu_seconds();
    struct AddCpu {  // also when a set throws
      double start;
      std::atomic<double>& total;
      ~AddCpu() { total.store(total.load() + thread_cpu_seconds() - start); }
    } add_cpu{cpu_start, cpu_seconds_};
    if (set.cameras.size() != results_.size())
      throw bad_input(fmt::format("stage 'quicklook': set {} has {} cameras but the recording has {}", set.set_index,
                                  set.cameras.size(), results_.size()));
    if (seen_any_ && set.set_index > last_set_ + 1) counts_.skipped += set.set_index - last_set_ - 1;
    seen_any_ = true;
    last_set_ = set.set_index;

    std::vector<double> backgrounds(results_.size(), quicklook::not_measured);
    // The cameras are independent: a second thread takes every other one, so that a set of
    // 2048^2 frames is measured within the trigger period on two cores. It is started from
    // this thread after its nice value was raised, so it inherits it.
    auto measure_cameras = [&](std::size_t first) {
      for (std::size_t c = first; c < results_.size(); c += 2) measure_camera(c, set.cameras[c], backgrounds[c]);
    };
    if (results_.size() > 1) {
      std::atomic<double> helper_cpu{0.0};
      std::exception_ptr helper_failure;
      std::thread helper([&] {
        const double start = thread_cpu_seconds();
        try {
          measure_cameras(1);
        } catch (...) {
          helper_failure = std::current_exception();  // rethrown on this thread, as if measured here
        }
        helper_cpu.store(thread_cpu_seconds() - start);
      });
      measure_cameras(0);
      helper.join();
      cpu_seconds_.store(cpu_seconds_.load() + helper_cpu.load());
      if (helper_failure) std::rethrow_exception(helper_failure);
    } else {
      measure_cameras(0);
    }
    ++counts_.analysed;

    PreviewSummary preview;
    DriftSummary drift;
    if (worker_) {
      const PreviewWorker::State s = worker_->state();
      preview = s.preview;
      drift = s.drift;
      counts_.previews = s.previews;
      counts_.previews_skipped = s.skipped;
      counts_.drift_alarm_sets = s.drift_alarm_sets;
    }
    if (publisher_) publish(set_message(set, results_, preview, drift, counts_, settings_.thumbnail_px));
    if (store_quicklook_) {
      store_quicklook_(statistics_record(set.set_index, results_));
      ++counts_.stored;
    }
    if (worker_) worker_->offer({set, std::move(backgrounds), taken});
  }

  void end() override {
    if (worker_) {
      worker_->finish();
      const PreviewWorker::State s = worker_->state();
      counts_.previews = s.previews;
      counts_.previews_skipped = s.skipped;
      counts_.drift_alarm_sets = s.drift_alarm_sets;
      final_state_ = s;
    }
  }

  nlohmann::json status() const override {
    nlohmann::json j = to_json(counts_);
    {
      std::lock_guard lock(publish_mutex_);
      j["published"] = published_;
      j["dropped"] = dropped_;
    }
    j["publish"] = publisher_ ? nlohmann::json(publisher_->endpoint()) : nlohmann::json(nullptr);
    const PreviewWorker::State s = worker_ ? worker_->state() : final_state_;
    j["mode"] = shadow_mode_ ? "shadow" : "particles";
    j["preview"] = preview_ == "off" || shadow_mode_ ? nlohmann::json("off")
                   : !s.disabled.empty() ? nlohmann::json(fmt::format("off: {}", s.disabled))
                                         : nlohmann::json(settings_.preview.algorithm);
    j["preview_failures"] = s.failures;
    j["cpu_seconds"] = cpu_seconds_.load();  // the statistics thread's, in process()
    j["preview_cpu_seconds"] = s.cpu_seconds;
    j["nice"] = {{"statistics", settings_.nice}, {"preview", settings_.preview_nice}};
    if (!priority_error_.empty()) j["nice_error"] = priority_error_;
    if (!s.priority_error.empty()) j["preview_nice_error"] = s.priority_error;
    if (!s.last_error.empty()) j["preview_error"] = s.last_error;
    j["preview_latency_s"] = {{"max", s.latency_max_s},
                              {"mean", s.previews > 0 ? nlohmann::json(s.latency_sum_s / static_cast<double>(s.previews))
                                                      : nlohmann::json(nullptr)}};
    j["latest_preview"] = to_json(s.preview);
    j["latest_drift"] = to_json(s.drift);
    return j;
  }

  bool may_skip() const override { return true; }
  // The statistics keep up with the rig on average (docs/performance.md, "Quick-look") but not
  // in every moment: the first sets after a start meet cold caches, and the recorder's writes
  // take the cores in bursts. Half a second of sets at 10 Hz may wait, so such a moment costs
  // a little latency instead of skipped statistics; the preview volume keeps only the newest.
  std::size_t max_waiting_sets() const override { return kStatisticsMayLagSets; }

 private:
  // A recording of a shadowgraphy rig: the spray-thesis simulation, or a rig whose light
  // sources are all LEDs (inline LED back-lighting, thesis Ch. 6-7).
  static bool is_shadowgraphy(const SessionDescription& recording) {
    if (recording.truth && recording.truth->case_name == "spray-thesis") return true;
    const config::RigConfig* rig = recording.rig_config();
    if (rig == nullptr || rig->trigger.light_sources.empty()) return false;
    for (const config::LightSourceConfig& source : rig->trigger.light_sources)
      if (source.kind != config::LightSourceKind::led) return false;
    return true;
  }

  // The preview volume and drift monitor need the cameras' models: the truth of a simulated
  // recording, or the rig's calibration. Without them the statistics still run. They are built
  // on the preview thread, so that begin() (on the recorder's thread) returns at once.
  void start_preview(const SessionDescription& recording, const QuickLookSettings& settings) {
    auto build = [recording, settings, calib = calib_]() {
      PreviewWorker::Parts parts;
      const SessionCameras cameras = session_cameras(recording, calib);
      const VoxelGrid grid = grid_from_session(recording);
      std::vector<calibration::ImageSize> sizes;
      for (const storage::SessionCamera& c : recording.cameras) sizes.push_back({c.width, c.height});
      parts.preview = std::make_unique<quicklook::PreviewVolume>(cameras.models, sizes, grid, settings.preview);
      if (cameras.models.size() >= 3) {
        quicklook::DriftOptions options = settings.drift;
        for (const storage::SessionCamera& c : recording.cameras) options.camera_names.push_back(c.id);
        const Vec3d low = grid.centre_of(-0.5, -0.5, -0.5);
        const Vec3d high = grid.centre_of(grid.nx - 0.5, grid.ny - 0.5, grid.nz - 0.5);
        parts.drift = std::make_unique<quicklook::DriftMonitor>(cameras.models, sizes,
                                                                calibration::VolumeBounds{low, high}, options);
      }
      return parts;
    };
    PreviewWorker::Outputs outputs;
    if (publisher_) outputs.publish = [this](stream::PreviewMessage m) { publish(m); };
    if (store_quicklook_) outputs.store = store_quicklook_;
    worker_ = std::make_unique<PreviewWorker>(std::move(build), recording.cameras.size(), std::move(outputs),
                                              settings.preview_nice);
  }

  // Both threads publish: one socket, used by one at a time.
  void publish(const stream::PreviewMessage& message) {
    std::lock_guard lock(publish_mutex_);
    if (publisher_->publish(message)) ++published_;
    else ++dropped_;
  }

  std::string publish_;
  bool allow_remote_ = false;
  bool store_ = true;
  std::string preview_ = "on";
  std::optional<int> threads_;
  int thumbnail_px_ = QuickLookSettings{}.thumbnail_px;
  int nice_ = QuickLookSettings{}.nice;
  int preview_nice_ = QuickLookSettings{}.preview_nice;
  bool priority_lowered_ = false;
  std::atomic<double> cpu_seconds_{0.0};
  std::string priority_error_;
  std::string calib_;
  std::string shadow_ = "auto";
  bool shadow_mode_ = false;
  std::vector<quicklook::ShadowLook> shadow_looks_;

  QuickLookSettings settings_;
  std::function<void(const storage::QuickLookRecord&)> store_quicklook_;
  std::vector<quicklook::QuickLook> statistics_;
  std::vector<quicklook::DtCheck> dt_checks_;
  std::vector<CameraResult> results_;
  Counts counts_;
  bool seen_any_ = false;
  std::uint64_t last_set_ = 0;
  std::unique_ptr<PreviewWorker> worker_;
  PreviewWorker::State final_state_;

  zmq::context_t context_{1};
  std::unique_ptr<stream::PreviewPublisher> publisher_;
  mutable std::mutex publish_mutex_;
  std::uint64_t published_ = 0, dropped_ = 0;
};

}  // namespace

std::unique_ptr<Stage> make_quicklook_stage() { return std::make_unique<QuickLookStage>(); }

}  // namespace tomorig::pipeline
