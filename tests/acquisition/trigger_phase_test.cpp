// When a two-trigger camera's triggers are moved past its readout grid (trigger_phase.h), with
// the answer latencies a 40 ms grid camera gives for each placement of its triggers.
#include <gtest/gtest.h>

#include <deque>

#include "tomorig/acquisition/trigger_phase.h"

namespace tomorig::acquisition {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kReadout = 40 * kMs;

TEST(TriggerPhase, TriggersWellPastTheirGridLineStayWhereTheyAre) {
  // Sent 5-15 ms past a line: answered 25-35 ms later.
  EXPECT_EQ(trigger_phase_delay_ns({35 * kMs, 34 * kMs, 30 * kMs, 25 * kMs, 33 * kMs, 35 * kMs}, kReadout), 0);
}

TEST(TriggerPhase, TriggersJustBeforeTheirGridLineMoveAnEighthOfAReadoutPastIt) {
  // Sent 1-2 ms before a line: answered at once. Moved by the quickest answer + 5 ms.
  EXPECT_EQ(trigger_phase_delay_ns({2 * kMs, 1 * kMs, 2 * kMs, 1 * kMs}, kReadout), 1 * kMs + kReadout / 8);
}

TEST(TriggerPhase, FramesAAndBOnEitherSideOfTheirLinesAreMovedTogether) {
  // Frame A's trigger 0.1 ms before a line (answered at once), frame B's 0.1 ms after its line
  // (answered a readout later: every pair 120 ms apart against the plan's 80 ms). The first
  // two events had both just after their lines. The median (39.9 ms) says nothing is wrong;
  // the quickest answer moves A to 5 ms past its line, and B with it to 5.2 ms past its own.
  const std::deque<std::int64_t> latencies{39'900'000, 39'900'000, 39'900'000, 39'900'000,
                                           100'000,    39'900'000, 100'000,    39'900'000};
  const std::int64_t delay = trigger_phase_delay_ns(latencies, kReadout);
  EXPECT_EQ(delay, 100'000 + kReadout / 8);
  // Where each trigger lands after the delay, relative to its grid line (answered at the next).
  const std::int64_t a_past_line = -100'000 + delay, b_past_line = 100'000 + delay;
  EXPECT_GT(a_past_line, 4 * kMs);
  EXPECT_LT(b_past_line, kReadout - 30 * kMs);  // most of a readout to spare for host delays
}

TEST(TriggerPhase, NothingToJudgeByMeansNoDelay) {
  EXPECT_EQ(trigger_phase_delay_ns({}, kReadout), 0);
  EXPECT_EQ(trigger_phase_delay_ns({1 * kMs, 2 * kMs}, 0), 0);  // readout unknown
}

}  // namespace
}  // namespace tomorig::acquisition
