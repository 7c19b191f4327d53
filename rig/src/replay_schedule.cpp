#include "tomorig/rig/replay_schedule.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/core/set_selection.h"

namespace tomorig::rig {
ReplayRate parse_replay_rate(const std::string& text) {
  if (text == "recorded") return {ReplayRate::Mode::recorded, 0.0};
  if (text == "max") return {ReplayRate::Mode::max, 0.0};
  double hz = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), hz);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(hz) || hz <= 0.0)
    throw bad_input(fmt::format("--rate '{}' is invalid: use recorded, max, or a rate in Hz above 0 (e.g. 25)", text));
  return {ReplayRate::Mode::fixed, hz};
}

SetRange parse_set_range(const std::string& text, std::uint64_t set_count) {
  const auto [first, end] = SetSelection::parse(text).range(set_count);  // the one set syntax
  return {first, end};
}

ReplaySchedule make_replay_schedule(const ReplayRate& rate, const std::vector<std::int64_t>& trigger_ns) {
  using std::chrono::nanoseconds;
  ReplaySchedule s;
  const std::size_t n = trigger_ns.size();
  s.due.assign(n, nanoseconds(0));
  if (n == 0 || rate.mode == ReplayRate::Mode::max) return s;
  if (rate.mode == ReplayRate::Mode::fixed) {
    const double period_ns = 1e9 / rate.hz;
    for (std::size_t i = 0; i < n; ++i) s.due[i] = nanoseconds(static_cast<std::int64_t>(std::llround(period_ns * i)));
    s.pass_length = nanoseconds(static_cast<std::int64_t>(std::llround(period_ns * n)));
    return s;
  }
  std::int64_t offset = 0;
  for (std::size_t i = 1; i < n; ++i) {
    offset += std::max<std::int64_t>(0, trigger_ns[i] - trigger_ns[i - 1]);
    s.due[i] = nanoseconds(offset);
  }
  // The next pass follows after one mean recorded interval (one set alone: at once).
  s.pass_length = n > 1 ? nanoseconds(offset + offset / static_cast<std::int64_t>(n - 1)) : nanoseconds(0);
  return s;
}

}  // namespace tomorig::rig
