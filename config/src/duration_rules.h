#pragma once
// Rules for the trigger's times and safety limits. The trigger module works in integer
// nanoseconds, so a positive time must be at least 1 ns to survive the conversion; configured
// safety limits have ceilings so that no entry can switch a limit off (docs/configuration.md).
#include <optional>
#include <string>

#include "rules.h"

namespace tomorig::config::detail {

inline constexpr double kTimeStepUs = 0.001;  // 1 ns: the trigger module's time step

// A duration that must be > 0 after rounding to whole nanoseconds.
inline Rule<double> positive_duration_us() {
  return {[](const double& v) -> std::optional<std::string> {
    if (v >= kTimeStepUs) return std::nullopt;
    return std::string("must be >= 0.001 (1 ns, the trigger's time step)");
  }};
}

// low <= v <= high with the reason for the bounds, e.g. a safety limit's ceiling.
inline Rule<double> in_range_because(double low, bool low_inclusive, double high, std::string why) {
  return {[=](const double& v) -> std::optional<std::string> {
    const bool above_low = low_inclusive ? v >= low : v > low;
    if (above_low && v <= high) return std::nullopt;
    return fmt::format("must be in {}{}, {}] ({})", low_inclusive ? "[" : "(", low, high, why);
  }};
}

}  // namespace tomorig::config::detail
