#include "tomorig/trigger/clock.h"

#include <chrono>
#include <condition_variable>
#include <mutex>

namespace tomorig::trigger {
namespace {

class SteadyClock final : public Clock {
 public:
  std::int64_t now_ns() override {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
  }
  bool wait_until_ns(std::int64_t t_ns, std::stop_token stop) override {
    const std::chrono::steady_clock::time_point deadline{std::chrono::nanoseconds(t_ns)};
    std::mutex m;
    std::condition_variable_any cv;  // woken by the stop request, never notified otherwise
    std::unique_lock lock(m);
    cv.wait_until(lock, stop, deadline, [] { return false; });
    return !stop.stop_requested();
  }
};

}  // namespace

std::shared_ptr<Clock> steady_clock() { return std::make_shared<SteadyClock>(); }

}  // namespace tomorig::trigger
