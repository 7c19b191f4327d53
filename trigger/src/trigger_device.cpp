// The shared part of every trigger device: checks before arming, a worker thread that asks the
// backend for one event after another, and a bounded queue the consumer reads.
#include "tomorig/trigger/trigger_device.h"

#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>
#include <utility>

#include "tomorig/core/error.h"

namespace tomorig::trigger {

struct TriggerDevice::Impl {
  std::unique_ptr<DeviceBackend> backend;
  std::vector<LightSource> light_sources;
  std::size_t capacity = 256;
  std::optional<TimingPlan> plan;

  std::mutex mutex;
  std::condition_variable_any changed;  // an event was queued or taken, or the run ended
  std::deque<TriggerEvent> queue;
  bool running = false;  // a run was started and its worker has not finished
  std::uint64_t dropped = 0;
  // Events dropped and not yet taken by the consumer, so their sets still get the real
  // trigger time and Δt. Bounded: a consumer that never asks cannot grow it without end.
  std::deque<TriggerEvent> dropped_untaken;
  static constexpr std::size_t kMaxDroppedKept = 65536;
  std::exception_ptr error;
  std::jthread worker;

  // false: stop was requested while waiting for room.
  bool push(const TriggerEvent& event, std::stop_token stop) {
    std::unique_lock lock(mutex);
    if (backend->paced()) {
      if (queue.size() >= capacity) {
        ++dropped;
        if (dropped_untaken.size() < kMaxDroppedKept) dropped_untaken.push_back(event);
        return true;
      }
    } else if (!changed.wait(lock, stop, [&] { return queue.size() < capacity; })) {
      return false;
    }
    queue.push_back(event);
    changed.notify_all();
    return true;
  }

  void run(std::stop_token stop, std::optional<std::uint64_t> events) {
    try {
      backend->begin();
      for (std::uint64_t k = 0; !events || k < *events; ++k) {
        if (stop.stop_requested()) break;
        std::optional<TriggerEvent> event = backend->fire(k, stop);
        if (!event || !push(*event, stop)) break;
      }
    } catch (...) {
      std::lock_guard lock(mutex);
      error = std::current_exception();
    }
    try {
      backend->end();
    } catch (...) {
      std::lock_guard lock(mutex);
      if (!error) error = std::current_exception();
    }
    std::lock_guard lock(mutex);
    running = false;
    changed.notify_all();
  }

  void join() {
    if (worker.joinable()) {
      worker.request_stop();
      worker.join();
    }
  }

  // Called with the lock held: an event, or nullopt when the run is over and drained.
  std::optional<TriggerEvent> take(std::unique_lock<std::mutex>&) {
    if (!queue.empty()) {
      TriggerEvent e = queue.front();
      queue.pop_front();
      changed.notify_all();
      return e;
    }
    if (error) std::rethrow_exception(std::exchange(error, nullptr));
    return std::nullopt;
  }
};

TriggerDevice::TriggerDevice(std::unique_ptr<DeviceBackend> backend, std::vector<LightSource> light_sources,
                             std::size_t queue_capacity)
    : impl_(std::make_unique<Impl>()) {
  if (!backend) throw bad_input("TriggerDevice needs a backend");
  if (queue_capacity == 0) throw bad_input("TriggerDevice: queue capacity must be >= 1");
  impl_->backend = std::move(backend);
  impl_->light_sources = std::move(light_sources);
  impl_->capacity = queue_capacity;
}

TriggerDevice::~TriggerDevice() { impl_->join(); }

DeviceCapabilities TriggerDevice::capabilities() const { return impl_->backend->capabilities(); }

void TriggerDevice::arm(const TimingPlan& plan) {
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->running) throw runtime_error("cannot arm the trigger device while it is running; stop() it first");
  }
  impl_->join();
  impl_->plan.reset();
  enforce_safety_limits(plan, impl_->light_sources);
  require_capabilities(plan, impl_->backend->capabilities());
  impl_->backend->arm(plan);
  impl_->plan = plan;
}

bool TriggerDevice::armed() const { return impl_->plan.has_value(); }

void TriggerDevice::start(std::optional<std::uint64_t> events) {
  if (!impl_->plan) throw runtime_error("the trigger device was started before arm(plan)");
  std::lock_guard lock(impl_->mutex);
  if (impl_->running) throw runtime_error("the trigger device is already running");
  if (impl_->worker.joinable()) impl_->worker.join();  // the previous run has finished
  impl_->queue.clear();
  impl_->dropped = 0;
  impl_->dropped_untaken.clear();
  impl_->error = nullptr;
  impl_->running = true;
  impl_->worker = std::jthread([impl = impl_.get(), events](std::stop_token stop) { impl->run(stop, events); });
}

void TriggerDevice::stop() { impl_->join(); }

std::optional<TriggerEvent> TriggerDevice::next_event() {
  std::unique_lock lock(impl_->mutex);
  impl_->changed.wait(lock, [&] { return !impl_->queue.empty() || !impl_->running; });
  return impl_->take(lock);
}

std::optional<TriggerEvent> TriggerDevice::next_event_for(std::chrono::nanoseconds timeout) {
  std::unique_lock lock(impl_->mutex);
  if (!impl_->changed.wait_for(lock, timeout, [&] { return !impl_->queue.empty() || !impl_->running; }))
    return std::nullopt;
  return impl_->take(lock);
}

std::uint64_t TriggerDevice::dropped_events() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->dropped;
}

std::vector<TriggerEvent> TriggerDevice::take_dropped_events() {
  std::lock_guard lock(impl_->mutex);
  std::vector<TriggerEvent> out(impl_->dropped_untaken.begin(), impl_->dropped_untaken.end());
  impl_->dropped_untaken.clear();
  return out;
}

std::size_t TriggerDevice::queued_events() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->queue.size();
}

std::size_t TriggerDevice::queue_capacity() const { return impl_->capacity; }

}  // namespace tomorig::trigger
