#pragma once
// Rules for the trigger's times and safety limits. The trigger module works in integer
// nanoseconds, so a positive time must be at least 1 ns to survive the conversion; configured
// safety limits have ceilings so that no entry can switch a limit off (docs/configuration.md).
#include <optional>
#include <string>

#include "rules.h"

namespace tomorig::config::detail {

inline constexpr double kTimeStepUs = 0.001;  // 1 ns: the trigger module's time step

// The ceiling of every time in the rig file, checked before any arithmetic: 1000 s. Trigger
// times are int64 nanoseconds, which wrap at 9.2e15 us (llround of a larger value is undefined);
// with every time below 1e9 us, sums and products of a few of them stay far from that, and no
// PIV timing (a pulse, a delay, a period, an exposure) comes near 1000 s.
inline constexpr double kMaxDurationUs = 1e9;
// Rates whose period is within that ceiling, and at most 1 MHz (a 1 us period).
inline constexpr double kMinRateHz = 1e6 / kMaxDurationUs;
inline constexpr double kMaxRateHz = 1e6;

// A time in us that `rule` accepts and that is at most kMaxDurationUs.
inline Rule<double> bounded_time_us(Rule<double> rule) {
  return and_at_most(std::move(rule), kMaxDurationUs, "1000 s, the longest time a rig file may give");
}

// A duration that must be > 0 after rounding to whole nanoseconds, and at most 1000 s.
inline Rule<double> positive_duration_us() {
  return bounded_time_us({[](const double& v) -> std::optional<std::string> {
    if (v >= kTimeStepUs) return std::nullopt;
    return std::string("must be >= 0.001 (1 ns, the trigger's time step)");
  }});
}

// A delay or gap: >= 0 and at most 1000 s.
inline Rule<double> non_negative_time_us() { return bounded_time_us(at_least(0.0)); }

// low <= v <= high with the reason for the bounds, e.g. a safety limit's ceiling.
inline Rule<double> in_range_because(double low, bool low_inclusive, double high, std::string why) {
  return {[=](const double& v) -> std::optional<std::string> {
    const bool above_low = low_inclusive ? v >= low : v > low;
    if (above_low && v <= high) return std::nullopt;
    return fmt::format("must be in {}{}, {}] ({})", low_inclusive ? "[" : "(", low, high, why);
  }};
}

}  // namespace tomorig::config::detail
