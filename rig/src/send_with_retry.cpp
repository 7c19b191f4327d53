#include "tomorig/rig/send_with_retry.h"

#include <cerrno>
#include <chrono>
#include <string>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/rig/stop_signal.h"
#include "tomorig/core/error.h"

namespace tomorig::rig {
namespace {

template <typename Message>
SendOutcome retry(stream::FrameSender& sender, const Message& message, const std::string& what, double limit_s,
                  const StopSignalGuard* stop) {
  const auto begin = std::chrono::steady_clock::now();
  for (;;) {
    try {
      if (sender.send(message)) return SendOutcome::sent;
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR)
        throw runtime_error(fmt::format("sending {} on {} failed: {}", what, sender.endpoint(), e.what()));
    }
    if (stop != nullptr && stop->stop_requested()) return SendOutcome::stopped;
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    if (waited >= limit_s)
      throw runtime_error(fmt::format(
          "no receiver took {} within {:g} s on {}: the receiver is absent or stalled (is 'tomorig record --from "
          "{}' running? for a slow receiver raise --timeout, or --wait for the first message)",
          what, limit_s, sender.endpoint(), sender.endpoint()));
  }
}

}  // namespace

SendOutcome send_with_retry(stream::FrameSender& sender, const FrameSet& set, double limit_s,
                            const StopSignalGuard* stop) {
  return retry(sender, set, fmt::format("set {}", set.set_index), limit_s, stop);
}

SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SessionStart& start, double limit_s,
                            const StopSignalGuard* stop) {
  return retry(sender, start, "the session start", limit_s, stop);
}

SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SetTruth& truth, double limit_s,
                            const StopSignalGuard* stop) {
  return retry(sender, truth, fmt::format("the truth of trigger {}", truth.trigger_index), limit_s, stop);
}

SendOutcome send_with_retry(stream::FrameSender& sender, const stream::SessionEnd& end, double limit_s,
                            const StopSignalGuard* stop) {
  return retry(sender, end, "the session end", limit_s, stop);
}

}  // namespace tomorig::rig
