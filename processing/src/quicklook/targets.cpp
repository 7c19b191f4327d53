#include "tomorig/processing/quicklook/targets.h"

#include <fmt/format.h>

namespace tomorig::quicklook {

std::string_view to_string(Flag flag) {
  switch (flag) {
    case Flag::green: return "green";
    case Flag::amber: return "amber";
    case Flag::red: return "red";
  }
  return "red";
}

std::string Target::validate(std::string_view what) const {
  // Written as !(a <= b) so that NaN fails too.
  if (!(std::isfinite(low) && std::isfinite(high) && low >= 0.0 && low <= high && high > 0.0))
    return fmt::format("{}: target range [{}, {}] is not valid: need 0 <= low <= high and high > 0", what, low, high);
  if (!(std::isfinite(amber) && amber >= 0.0))
    return fmt::format("{}: amber band {} must be >= 0 (a fraction of the bound)", what, amber);
  return {};
}

Flag judge(double value, const Target& target) {
  if (!std::isfinite(value)) return Flag::red;
  if (value >= target.low && value <= target.high) return Flag::green;
  if (value >= target.low / (1.0 + target.amber) && value <= target.high * (1.0 + target.amber)) return Flag::amber;
  return Flag::red;
}

}  // namespace tomorig::quicklook
