#include "tomorig/rig/send_with_retry.h"

#include <cerrno>
#include <chrono>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/rig/stop_signal.h"
#include "tomorig/core/error.h"

namespace tomorig::rig {

SendOutcome send_with_retry(stream::FrameSender& sender, const FrameSet& set, double limit_s,
                            const StopSignalGuard* stop) {
  const auto begin = std::chrono::steady_clock::now();
  for (;;) {
    try {
      if (sender.send(set)) return SendOutcome::sent;
    } catch (const zmq::error_t& e) {
      if (e.num() != EINTR)
        throw runtime_error(fmt::format("sending set {} on {} failed: {}", set.set_index, sender.endpoint(), e.what()));
    }
    if (stop != nullptr && stop->stop_requested()) return SendOutcome::stopped;
    const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
    if (waited >= limit_s)
      throw runtime_error(fmt::format(
          "no receiver took set {} within {:g} s on {}: the receiver is absent or stalled (is 'tomorig record --from "
          "{}' running? for a slow receiver raise --timeout, or --wait for the first set)",
          set.set_index, limit_s, sender.endpoint(), sender.endpoint()));
  }
}

}  // namespace tomorig::rig
