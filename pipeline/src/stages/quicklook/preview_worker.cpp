#include "preview_worker.h"

#include <time.h>

#include <algorithm>
#include <exception>

#include <fmt/format.h>

#include "thread_priority.h"
#include "tomorig/core/error.h"

namespace tomorig::pipeline::quicklook_stage {
namespace {

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

}  // namespace

PreviewWorker::PreviewWorker(std::function<Parts()> build, std::size_t cameras, Outputs outputs, int nice)
    : build_(std::move(build)), cameras_(cameras), outputs_(std::move(outputs)), nice_(nice) {
  thread_ = std::thread([this] { work(); });
}

PreviewWorker::~PreviewWorker() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;
    mailbox_.reset();
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void PreviewWorker::offer(Job job) {
  {
    std::lock_guard lock(mutex_);
    if (closing_) return;
    if (mailbox_) ++state_.skipped;  // never reconstructed: a newer set replaces it
    mailbox_ = std::move(job);
  }
  changed_.notify_all();
}

void PreviewWorker::finish() {
  {
    std::lock_guard lock(mutex_);
    closing_ = true;  // the worker takes the waiting job first, then returns
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

PreviewWorker::State PreviewWorker::state() const {
  std::lock_guard lock(mutex_);
  return state_;
}

void PreviewWorker::work() {
  std::string error = lower_this_thread_priority(nice_);
  if (error.empty()) error = run_this_thread_only_when_idle();
  if (!error.empty()) {
    std::lock_guard lock(mutex_);
    state_.priority_error = std::move(error);
  }
  try {
    Parts parts = build_();
    preview_ = std::move(parts.preview);
    drift_ = std::move(parts.drift);
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    state_.disabled = e.what();
    closing_ = true;  // offers are ignored from here on
    mailbox_.reset();
    return;
  }
  std::unique_lock lock(mutex_);
  for (;;) {
    changed_.wait(lock, [&] { return mailbox_.has_value() || closing_; });
    if (!mailbox_) return;
    Job job = std::move(*mailbox_);
    mailbox_.reset();
    lock.unlock();
    const double cpu_start = thread_cpu_seconds();
    run(job);
    const double cpu = thread_cpu_seconds() - cpu_start;
    lock.lock();
    state_.cpu_seconds += cpu;
  }
}

void PreviewWorker::run(Job& job) {
  std::vector<Image> images;
  for (const CameraFrames& c : job.set.cameras) images.push_back(c.a.image);
  const std::uint64_t set = job.set.set_index;
  bool made = false;
  double latency = 0;
  const quicklook::DriftReport* drift = nullptr;
  try {
    for (const Image& image : images)
      if (image.empty()) throw bad_input("a frame A is missing, so this set has no preview volume");
    if (preview_) {
      preview_->reconstruct(images, result_, job.backgrounds);
      made = true;
      latency = std::chrono::duration<double>(Clock::now() - job.taken).count();
      std::lock_guard lock(mutex_);
      ++state_.previews;
      state_.preview = {true, set, result_.sheet, result_.active_voxels, result_.seconds, latency};
      state_.latency_max_s = std::max(state_.latency_max_s, latency);
      state_.latency_sum_s += latency;
    }
    // The drift monitor after the preview is out, so that it never delays the volume.
    if (made && outputs_.publish) {
      Counts counts;
      {
        std::lock_guard lock(mutex_);
        counts.previews = state_.previews;
        counts.previews_skipped = state_.skipped;
        counts.drift_alarm_sets = state_.drift_alarm_sets;
      }
      outputs_.publish(preview_message(set, result_, drift_ ? &drift_->report() : nullptr, latency, counts));
    }
    if (drift_) {
      drift = &drift_->add_set(images);
      std::lock_guard lock(mutex_);
      state_.drift = {true, set, drift->sets, drift->flag, drift->largest_px, {}};
      for (const quicklook::DriftAlarm& a : drift->alarms) state_.drift.alarms.push_back(a.message);
      if (!drift->alarms.empty()) ++state_.drift_alarm_sets;
    }
    if (outputs_.store && (made || drift != nullptr))
      outputs_.store(preview_record(set, cameras_, made ? &result_ : nullptr, drift));
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex_);
    ++state_.failures;
    state_.last_error = fmt::format("set {}: {}", set, e.what());
  }
}

}  // namespace tomorig::pipeline::quicklook_stage
