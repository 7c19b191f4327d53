#include "tomorig/acquisition/trigger_phase.h"

#include <algorithm>

namespace tomorig::acquisition {

std::int64_t trigger_phase_delay_ns(const std::deque<std::int64_t>& answer_latencies_ns, std::int64_t readout_ns) {
  if (readout_ns <= 0 || answer_latencies_ns.empty()) return 0;
  const std::int64_t quickest = *std::min_element(answer_latencies_ns.begin(), answer_latencies_ns.end());
  if (quickest >= readout_ns / 2) return 0;
  return std::max<std::int64_t>(quickest, 0) + readout_ns / 8;
}

}  // namespace tomorig::acquisition
