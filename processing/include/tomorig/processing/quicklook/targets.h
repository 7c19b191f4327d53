#pragma once
// Traffic-light judgement of quick-look figures against their targets. A figure inside its
// target range is green; outside it by less than the amber band it is amber; further out, or
// not measurable (NaN), it is red.
#include <cmath>
#include <limits>
#include <string>
#include <string_view>

namespace tomorig::quicklook {

enum class Flag : unsigned char { green = 0, amber = 1, red = 2 };

std::string_view to_string(Flag flag);
// The worse of two flags (red > amber > green).
inline Flag worst(Flag a, Flag b) { return a > b ? a : b; }

// Green range [low, high]. Amber reaches `amber` (a fraction) beyond each bound: down to
// low / (1 + amber) and up to high * (1 + amber). low = 0 means "no lower limit".
struct Target {
  double low = 0.0;
  double high = 0.0;
  double amber = 0.25;

  // Empty if valid (finite, 0 <= low <= high, high > 0, amber >= 0), else a message naming
  // `what` (e.g. "quicklook.ppp").
  std::string validate(std::string_view what) const;
};

Flag judge(double value, const Target& target);

constexpr double not_measured = std::numeric_limits<double>::quiet_NaN();

// A figure and its flag.
struct Judged {
  double value = not_measured;
  Flag flag = Flag::red;

  void set(double v, const Target& target) {
    value = v;
    flag = judge(v, target);
  }
  bool measured() const { return std::isfinite(value); }
};

}  // namespace tomorig::quicklook
