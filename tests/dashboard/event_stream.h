#pragma once
// A page's event stream (GET /events) read on a thread of its own, for tests that wait until
// a given text has arrived.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include <httplib.h>

namespace tomorig::testing {

class EventStream {
 public:
  EventStream(int port, std::string path = "/events") {
    thread_ = std::thread([this, port, path] {
      httplib::Client client("127.0.0.1", port);
      client.set_read_timeout(std::chrono::seconds(5));
      const auto result = client.Get(path, [this](const char* data, std::size_t size) {
        std::lock_guard lock(mutex_);
        text_.append(data, size);
        changed_.notify_all();
        return !stop_;
      });
      std::lock_guard lock(mutex_);
      ended_ = true;
      status_ = result ? result->status : -1;
      changed_.notify_all();
    });
  }
  ~EventStream() {
    stop_ = true;
    thread_.join();  // the server's keep-alive comment (every 2 s) lets the receiver stop
  }

  // True once `needle` has arrived, false if `timeout` passed or the stream ended first.
  bool wait_for(const std::string& needle, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return text_.find(needle) != std::string::npos || ended_; }) &&
           text_.find(needle) != std::string::npos;
  }
  std::string text() {
    std::lock_guard lock(mutex_);
    return text_;
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::string text_;
  bool ended_ = false;
  int status_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace tomorig::testing
