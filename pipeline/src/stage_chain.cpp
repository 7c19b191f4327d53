#include "tomorig/pipeline/stage_chain.h"

#include <chrono>
#include <condition_variable>
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

  // The worker of a skipping stage and its one-set mailbox.
  std::mutex mutex;
  std::condition_variable changed;
  std::optional<FrameSet> mailbox;
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
      changed.wait(lock, [&] { return mailbox.has_value() || closing; });
      if (!mailbox) return;  // closing and drained
      FrameSet set = std::move(*mailbox);
      mailbox.reset();
      busy = true;
      lock.unlock();
      const bool ok = run_one(set);
      lock.lock();
      busy = false;
      if (!ok) {
        failed = true;
        if (mailbox) ++report.skipped;  // never processed: the stage stopped
        mailbox.reset();
        return;
      }
    }
  }
};

StageRunner::StageRunner(std::string name, std::unique_ptr<Stage> stage) : impl_(std::make_unique<Impl>()) {
  impl_->report.name = std::move(name);
  impl_->skipping = stage->may_skip();
  impl_->stage = std::move(stage);
}

StageRunner::~StageRunner() {
  if (impl_->worker.joinable()) {
    {
      std::lock_guard lock(impl_->mutex);
      impl_->closing = true;
      impl_->mailbox.reset();
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
  if (s.mailbox) ++s.report.skipped;  // the waiting set is stale now: the newest replaces it
  s.mailbox = set;                    // shares the pixel buffers; no copy of the images
  s.changed.notify_all();
}

StageReport StageRunner::end() {
  Impl& s = *impl_;
  if (s.worker.joinable()) {
    {
      std::lock_guard lock(s.mutex);
      s.closing = true;  // the worker processes the set still waiting, then returns
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
