#pragma once
// Safety limits of light sources. An overdriven LED (the thesis runs an SST-90 at 270 A for
// 400 ns) dies within milliseconds if its pulse is too long or repeated too often; a
// flash-lamp laser must not be fired faster than its rated rate. These limits are enforced by
// TriggerDevice::arm(), the only way a plan reaches an output, so no configuration and no
// hand-built TimingPlan can exceed them.
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "tomorig/config/rig_vocabulary.h"

namespace tomorig::trigger {

struct TimingPlan;
struct LightSource;

// laser, led, or unknown (not said: the strictest limit of every kind applies); the rig file's
// words and to_string() are config's (rig_vocabulary.h).
using LightSourceKind = config::LightSourceKind;

// Unset fields take the built-in default of the source's kind (default_limits()).
struct SafetyLimits {
  std::optional<std::int64_t> max_pulse_width_ns;  // longest electrical high time of one pulse
  std::optional<double> max_duty_cycle;            // high time / period, in (0, 1]
  std::optional<double> max_rate_hz;               // trigger events per second it fires in
};

// Every field set.
struct ResolvedLimits {
  std::int64_t max_pulse_width_ns = 0;
  double max_duty_cycle = 0.0;
  double max_rate_hz = 0.0;
};

// Conservative built-in defaults:
//   led:     2 µs, duty 0.1 %, 1000 Hz   (overdriven: a few µs at most, low duty)
//   laser:  20 µs (Q-switch trigger input), duty 0.1 %, 30 Hz (flash-lamp heads: 10–30 Hz)
//   unknown: the smaller of the two for each limit.
ResolvedLimits default_limits(LightSourceKind kind);
ResolvedLimits resolve_limits(const LightSource& source);

// Throws tomorig::Error (bad_input) at the first limit a light or flash-lamp channel of `plan`
// exceeds, naming the limit, the light source and the value. Limits come from `sources` (the
// device's table), never from the plan; a channel whose source is not in the table gets the
// `unknown` defaults. Also rejects malformed plans (pulses outside the period, period <= 0).
void enforce_safety_limits(const TimingPlan& plan, const std::vector<LightSource>& sources);

}  // namespace tomorig::trigger
