#include "tomorig/pipeline/stage_chain.h"

#include <chrono>
#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <utility>

namespace tomorig::pipeline {
namespace {

using Clock = std::chrono::steady_clock;

std::string error_text(const std::exception_ptr& error) {
  try {
    std::rethrow_exception(error);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "unknown error";
  }
}

}  // namespace

struct StageRunner::Impl {
  std::unique_ptr<Stage> stage;
  StageReport report;
  bool skipping = false;

  // The worker of a skipping stage and the sets waiting for it (oldest first, at most
  // max_waiting; they share the pixel buffers, so a waiting set costs no copy).
  std::mutex mutex;
  std::condition_variable changed;
  std::deque<FrameSet> waiting;
  std::size_t max_waiting = 1;
  bool busy = false;
  bool closing = false;
  bool failed = false;
  std::thread worker;

  // Runs process() with the timing and counting; returns false after an error (then recorded).
  bool run_one(const FrameSet& set) {
    const auto start = Clock::now();
    try {
      stage->process(set);
    } catch (...) {
      report.busy_seconds += std::chrono::duration<double>(Clock::now() - start).count();
      if (!skipping) throw;  // a stage that sees every set: the caller decides
      report.error = error_text(std::current_exception());
      return false;
    }
    report.busy_seconds += std::chrono::duration<double>(Clock::now() - start).count();
    ++report.processed;
    return true;
  }

  void work() {
    std::unique_lock lock(mutex);
    for (;;) {
      changed.wait(lock, [&] { return !waiting.empty() || closing; });
      if (waiting.empty()) return;  // closing and drained
      FrameSet set = std::move(waiting.front());
      waiting.pop_front();
      busy = true;
      lock.unlock();
      const bool ok = run_one(set);
      lock.lock();
      busy = false;
      if (!ok) {
        failed = true;
        report.skipped += waiting.size();  // never processed: the stage stopped
        waiting.clear();
        return;
      }
    }
  }
};

StageRunner::StageRunner(std::string name, std::unique_ptr<Stage> stage) : impl_(std::make_unique<Impl>()) {
  impl_->report.name = std::move(name);
  impl_->skipping = stage->may_skip();
  impl_->max_waiting = std::max<std::size_t>(1, stage->max_waiting_sets());
  impl_->stage = std::move(stage);
}

StageRunner::~StageRunner() {
  if (impl_->worker.joinable()) {
    {
      std::lock_guard lock(impl_->mutex);
      impl_->closing = true;
      impl_->waiting.clear();
    }
    impl_->changed.notify_all();
    impl_->worker.join();
  }
}

const std::string& StageRunner::name() const { return impl_->report.name; }

void StageRunner::begin(const SessionDescription& recording) {
  impl_->stage->begin(recording);
  if (impl_->skipping) impl_->worker = std::thread([this] { impl_->work(); });
}

void StageRunner::offer(const FrameSet& set) {
  Impl& s = *impl_;
  ++s.report.offered;
  if (!s.skipping) {
    s.run_one(set);
    return;
  }
  std::lock_guard lock(s.mutex);
  if (s.failed) {
    ++s.report.skipped;
    return;
  }
  if (s.waiting.size() >= s.max_waiting) {  // the oldest waiting set is stale now
    s.waiting.pop_front();
    ++s.report.skipped;
  }
  s.waiting.push_back(set);  // shares the pixel buffers; no copy of the images
  s.changed.notify_all();
}

StageReport StageRunner::end() {
  Impl& s = *impl_;
  if (s.worker.joinable()) {
    {
      std::lock_guard lock(s.mutex);
      s.closing = true;  // the worker processes the sets still waiting, then returns
    }
    s.changed.notify_all();
    s.worker.join();
  }
  if (s.report.error.empty()) s.stage->end();
  s.report.status = s.stage->status();
  return s.report;
}

void StageChain::add(std::string name, std::unique_ptr<Stage> stage) {
  runners_.push_back(std::make_unique<StageRunner>(std::move(name), std::move(stage)));
}

void StageChain::begin(const SessionDescription& recording) {
  for (auto& runner : runners_) runner->begin(recording);
}

void StageChain::push(const FrameSet& set) {
  for (auto& runner : runners_) runner->offer(set);
}

std::vector<StageReport> StageChain::end() {
  std::vector<StageReport> reports;
  for (auto& runner : runners_) reports.push_back(runner->end());
  return reports;
}

}  // namespace tomorig::pipeline
