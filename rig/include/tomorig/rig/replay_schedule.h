#pragma once
// When `tomorig replay` sends each set: at the recorded trigger times, as fast as possible,
// or at a fixed rate. Pure arithmetic, so the command's loop only waits and sends.
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tomorig::rig {

struct ReplayRate {
  enum class Mode { recorded, max, fixed } mode = Mode::recorded;
  double hz = 0.0;  // fixed mode only
};

// "recorded", "max" or a rate in Hz (> 0); bad_input otherwise.
ReplayRate parse_replay_rate(const std::string& text);

// Half-open range [first, last) of set indices, from the one set syntax (core/set_selection.h):
// "N" (the first N), "A:B", "A:" (to the end), ":B", or consecutive "A-B".
struct SetRange {
  std::uint64_t first = 0;
  std::uint64_t last = 0;
};
// bad_input if malformed, empty or beyond `set_count`.
SetRange parse_set_range(const std::string& text, std::uint64_t set_count);

// Offsets from the start of a pass at which each set is due, and the length of a pass (when
// the next --loop pass starts). `trigger_ns` are the recorded trigger timestamps of the sets
// in sending order; the offsets never run backwards, even if the timestamps do.
struct ReplaySchedule {
  std::vector<std::chrono::nanoseconds> due;
  std::chrono::nanoseconds pass_length{0};
};
ReplaySchedule make_replay_schedule(const ReplayRate& rate, const std::vector<std::int64_t>& trigger_ns);

}  // namespace tomorig::rig
