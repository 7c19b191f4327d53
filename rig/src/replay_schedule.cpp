#include "tomorig/rig/replay_schedule.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::rig {
namespace {

std::optional<std::uint64_t> parse_index(const std::string& text) {
  std::uint64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

}  // namespace

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
  const auto colon = text.find(':');
  std::optional<std::uint64_t> first, last;
  if (colon == std::string::npos) {
    first = parse_index(text);
    if (first) last = *first + 1;
  } else {
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    first = a.empty() ? std::optional<std::uint64_t>(0) : parse_index(a);
    last = b.empty() ? std::optional<std::uint64_t>(set_count) : parse_index(b);
  }
  if (!first || !last)
    throw bad_input(fmt::format("--sets '{}' is invalid: use A:B (sets A to B-1), A:, :B or A, with set indices "
                                "from 0", text));
  if (*first >= *last || *last > set_count)
    throw bad_input(fmt::format("--sets '{}' selects no sets of this session: it holds sets 0 to {} "
                                "(A:B sends sets A to B-1)", text, set_count == 0 ? 0 : set_count - 1));
  return {*first, *last};
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
