#pragma once
// The time base a paced trigger device waits on. Real devices use steady_clock(); tests pass a
// virtual clock whose waits return at once, so event timing is exact and nothing sleeps.
#include <cstdint>
#include <memory>
#include <stop_token>

namespace tomorig::trigger {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual std::int64_t now_ns() = 0;
  // Returns when now_ns() >= t_ns (true) or as soon as `stop` is requested (false).
  virtual bool wait_until_ns(std::int64_t t_ns, std::stop_token stop) = 0;
};

// std::chrono::steady_clock; waits wake early on a stop request.
std::shared_ptr<Clock> steady_clock();

}  // namespace tomorig::trigger
