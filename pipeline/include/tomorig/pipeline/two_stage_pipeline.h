#pragma once
// A bounded two-stage pipeline: a producer thread makes items (reconstructed volume pairs) while
// the calling thread consumes earlier ones (correlation and writing), so the two stages of
// different sets overlap. At most `capacity` items wait between the stages, which bounds memory.
// An exception in either stage stops both and is rethrown by run() in the calling thread.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

namespace tomorig::pipeline {

template <typename Item>
class TwoStagePipeline {
 public:
  // `produce(stop)` returns the next item, or nullopt when there is none left; it should return
  // soon after `stop()` turns true. `consume(item)` returns false to stop the pipeline.
  using Producer = std::function<std::optional<Item>(const std::function<bool()>& stop)>;
  using Consumer = std::function<bool(Item&)>;

  explicit TwoStagePipeline(std::size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}

  void run(const Producer& produce, const Consumer& consume) {
    std::thread producer([&] {
      try {
        const std::function<bool()> stop = [&] { return stopping(); };
        while (!stopping()) {
          std::optional<Item> item = produce(stop);
          std::unique_lock lock(mutex_);
          if (!item) break;
          changed_.wait(lock, [&] { return stop_ || queue_.size() < capacity_; });
          if (stop_) break;
          queue_.push_back(std::move(*item));
          changed_.notify_all();
        }
      } catch (...) {
        std::lock_guard lock(mutex_);
        error_ = std::current_exception();
        stop_ = true;
      }
      std::lock_guard lock(mutex_);
      done_ = true;
      changed_.notify_all();
    });
    try {
      for (;;) {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [&] { return !queue_.empty() || done_; });
        if (queue_.empty()) break;  // done and drained (or the producer failed)
        Item item = std::move(queue_.front());
        queue_.pop_front();
        changed_.notify_all();
        lock.unlock();
        if (!consume(item)) {
          request_stop();
          break;
        }
      }
    } catch (...) {
      request_stop();
      producer.join();
      throw;
    }
    request_stop();
    producer.join();
    if (error_) std::rethrow_exception(error_);
  }

  void request_stop() {
    std::lock_guard lock(mutex_);
    stop_ = true;
    changed_.notify_all();
  }

 private:
  bool stopping() {
    std::lock_guard lock(mutex_);
    return stop_;
  }

  std::size_t capacity_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Item> queue_;
  bool stop_ = false;
  bool done_ = false;
  std::exception_ptr error_;
};

}  // namespace tomorig::pipeline
