#pragma once
// The quick-look's slow path on its own thread: the preview volume and the drift monitor of
// the newest set it is given. A set offered while it works waits in a one-set mailbox; a newer
// one replaces it, and the replaced set counts as skipped, so the preview stays current
// however long a volume takes, and never holds back the statistics of every set.
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "quicklook_report.h"

namespace tomorig::pipeline::quicklook_stage {

class PreviewWorker {
 public:
  using Clock = std::chrono::steady_clock;
  struct Job {
    FrameSet set;                      // shares the pixels; nothing is copied
    std::vector<double> backgrounds;   // per camera, frame A, counts (NaN: estimate)
    Clock::time_point taken;           // when the stage took the set
  };
  struct Outputs {
    std::function<void(stream::PreviewMessage)> publish;        // may be empty
    std::function<void(const storage::QuickLookRecord&)> store;  // may be empty
  };

  // The preview volume and the drift monitor, either may be null (then that part is not run).
  struct Parts {
    std::unique_ptr<quicklook::PreviewVolume> preview;
    std::unique_ptr<quicklook::DriftMonitor> drift;
  };
  // `build` makes the parts on the worker's own thread (working out the grid a camera sees
  // takes a moment the recorder must not wait for); if it throws, the worker stops, offers are
  // ignored and state().disabled says why. The thread runs at nice value `nice`
  // (thread_priority.h), below the recorder and the statistics.
  PreviewWorker(std::function<Parts()> build, std::size_t cameras, Outputs outputs, int nice);
  ~PreviewWorker();  // stops without processing the waiting job
  PreviewWorker(const PreviewWorker&) = delete;
  PreviewWorker& operator=(const PreviewWorker&) = delete;

  void offer(Job job);
  // Processes the job still waiting (the newest), then stops the thread. Call once.
  void finish();

  struct State {
    PreviewSummary preview;
    DriftSummary drift;
    std::uint64_t previews = 0, skipped = 0, failures = 0, drift_alarm_sets = 0;
    double latency_max_s = 0, latency_sum_s = 0;  // from the stage taking a set to its preview done
    double cpu_seconds = 0;  // the worker thread's CPU time on jobs
    std::string last_error;  // of the last job that failed, e.g. a frame without light
    std::string disabled;    // why there is no preview (no camera models, ...); empty: running
    std::string priority_error;  // why the thread's nice value could not be raised; empty: it was
  };
  State state() const;

 private:
  void work();
  void run(Job& job);

  std::function<Parts()> build_;
  std::unique_ptr<quicklook::PreviewVolume> preview_;
  std::unique_ptr<quicklook::DriftMonitor> drift_;
  std::size_t cameras_;
  Outputs outputs_;
  int nice_;
  quicklook::PreviewResult result_;  // reused

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<Job> mailbox_;
  bool closing_ = false;
  State state_;
  std::thread thread_;
};

}  // namespace tomorig::pipeline::quicklook_stage
