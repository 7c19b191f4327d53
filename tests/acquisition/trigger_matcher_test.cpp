// Frames of software-triggered cameras matched to their triggers by time: a trigger the camera
// missed shifts no later frame into another set, and a frame near no trigger joins none.
#include "tomorig/acquisition/trigger_matcher.h"

#include <gtest/gtest.h>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kCameraClock = 987'654 * kMs;  // the camera's clock: any origin

// Two triggers a set at 5 Hz, 60 ms apart: event k's triggers at 200k and 200k + 60 ms.
void expect_events(TriggerMatcher& m, std::uint64_t events) {
  for (std::uint64_t k = 0; k < events; ++k) {
    const auto t = static_cast<std::int64_t>(k) * 200 * kMs;
    m.expect({k, Exposure::A, t});
    m.expect({k, Exposure::B, t + 60 * kMs});
  }
}

TEST(TriggerMatcher, FramesAnswerTheirOwnTriggersDespiteLatencyJitter) {
  TriggerMatcher m(1, 30 * kMs);
  expect_events(m, 4);
  // The camera answers 0-40 ms late (Aravis's GigE fake: its 40 ms trigger grid shifts
  // consecutive latencies by 20 ms at most here), on its own clock.
  const std::int64_t latency[8] = {5, 25, 30, 10, 0, 20, 12, 31};
  for (std::uint64_t k = 0; k < 4; ++k)
    for (int e = 0; e < 2; ++e) {
      const std::int64_t t = static_cast<std::int64_t>(k) * 200 * kMs + e * 60 * kMs + latency[2 * k + e] * kMs;
      const auto hit = m.match(2 * k + e, kCameraClock + t);
      ASSERT_TRUE(hit) << "event " << k;
      EXPECT_EQ(hit->event, k);
      EXPECT_EQ(hit->exposure, e == 0 ? Exposure::A : Exposure::B);
    }
  EXPECT_EQ(m.triggers_lost(), 0u);
}

TEST(TriggerMatcher, ATriggerTheCameraMissedShiftsNothing) {
  TriggerMatcher m(1, 30 * kMs);
  expect_events(m, 3);
  // Frame B of event 0 never came (the trigger was lost); counting frames would pair event
  // 1's A with event 0's A and shift every later frame.
  ASSERT_EQ(m.match(0, kCameraClock + 10 * kMs)->event, 0u);
  const auto a1 = m.match(1, kCameraClock + 210 * kMs);
  ASSERT_TRUE(a1);
  EXPECT_EQ(a1->event, 1u);
  EXPECT_EQ(a1->exposure, Exposure::A);
  const auto b1 = m.match(2, kCameraClock + 270 * kMs);
  ASSERT_TRUE(b1);
  EXPECT_EQ(b1->event, 1u);
  EXPECT_EQ(b1->exposure, Exposure::B);
  EXPECT_EQ(m.triggers_lost(), 1u);
}

TEST(TriggerMatcher, AWarmUpFrameAnswersNoEventAndAStrayFrameNone) {
  TriggerMatcher m(1, 30 * kMs);
  m.expect({std::nullopt, Exposure::A, -500 * kMs});  // warm-up, its frame 90 ms late
  expect_events(m, 1);
  const auto warm = m.match(0, kCameraClock - 410 * kMs);
  ASSERT_TRUE(warm);
  EXPECT_FALSE(warm->event);

  // The warm-up's 90 ms answer (a camera not ready yet) teaches nothing: event 0's trigger,
  // answered in 10 ms, is still the one its frame answers.
  EXPECT_EQ(m.match(2, kCameraClock + 10 * kMs)->event, 0u);
}

TEST(TriggerMatcher, AFrameNearNoTriggerJoinsNoSet) {
  TriggerMatcher m(1, 30 * kMs);
  expect_events(m, 2);
  ASSERT_EQ(m.match(0, kCameraClock + 10 * kMs)->event, 0u);
  EXPECT_FALSE(m.match(1, kCameraClock + 130 * kMs)) << "a frame between triggers joined a set";
  EXPECT_EQ(m.frames_unmatched(), 1u);
  EXPECT_EQ(m.match(2, kCameraClock + 75 * kMs)->exposure, Exposure::B);
}

TEST(TriggerMatcher, DoubleFrameCamerasGiveFrameBRightAfterFrameA) {
  TriggerMatcher m(2, 100 * kMs);
  for (std::uint64_t k = 0; k < 3; ++k) m.expect({k, Exposure::A, static_cast<std::int64_t>(k) * 200 * kMs});
  EXPECT_EQ(m.match(10, kCameraClock)->exposure, Exposure::A);
  const auto b0 = m.match(11, kCameraClock + 20'120);
  EXPECT_EQ(b0->event, 0u);
  EXPECT_EQ(b0->exposure, Exposure::B);
  // Event 1's trigger was missed: both of its frames are absent, event 2's come next.
  const auto a2 = m.match(12, kCameraClock + 400 * kMs);
  EXPECT_EQ(a2->event, 2u);
  EXPECT_EQ(a2->exposure, Exposure::A);
  EXPECT_EQ(m.match(13, kCameraClock + 400 * kMs + 20'120)->exposure, Exposure::B);
  EXPECT_EQ(m.triggers_lost(), 1u);
}

// Frames whose partner was lost: with the burst position from the frame counter, a lone
// frame B stays B of its own trigger and the next trigger's frame A is not taken for its B.
TEST(TriggerMatcher, ALoneFrameBKeepsItsRoleAndTrigger) {
  TriggerMatcher m(2, 100 * kMs);
  for (std::uint64_t k = 0; k < 4; ++k) m.expect({k, Exposure::A, static_cast<std::int64_t>(k) * 200 * kMs});
  EXPECT_EQ(m.match(0, kCameraClock, Exposure::A)->exposure, Exposure::A);
  EXPECT_EQ(m.match(1, kCameraClock + 300'000, Exposure::B)->exposure, Exposure::B);
  // Event 1's frame A (id 2) was lost: its frame B comes alone.
  const auto b1 = m.match(3, kCameraClock + 200 * kMs + 300'000, Exposure::B);
  ASSERT_TRUE(b1);
  EXPECT_EQ(b1->event, 1u);
  EXPECT_EQ(b1->exposure, Exposure::B);
  // Event 2's frame B (id 5) was lost: frame A of event 3 (id 6) follows frame A of event 2.
  const auto a2 = m.match(4, kCameraClock + 400 * kMs, Exposure::A);
  EXPECT_EQ(a2->event, 2u);
  EXPECT_EQ(a2->exposure, Exposure::A);
  const auto a3 = m.match(6, kCameraClock + 600 * kMs, Exposure::A);
  EXPECT_EQ(a3->event, 3u);
  EXPECT_EQ(a3->exposure, Exposure::A);
  EXPECT_EQ(m.triggers_lost(), 0u);
  // Without the position (the old behaviour), a lone B would have been taken for a frame A.
  TriggerMatcher blind(2, 100 * kMs);
  blind.expect({0, Exposure::A, 0});
  EXPECT_EQ(blind.match(1, kCameraClock + 300'000)->exposure, Exposure::A);
}

// A double-frame camera whose very first frame never reached the host: the frame counter's
// parity (taken from the first frame received) calls every later frame A a B and every B an A.
// With the plan's burst separation the matcher sees that the frame after the first is not its
// B (it comes a period later, not 1 ms): the parity flips back, and from the second event on
// every frame has its own role and event (before: every frame A became B of the event before).
TEST(TriggerMatcher, AFirstFrameLostEntirelyDoesNotSwapTheRolesOfTheRun) {
  constexpr std::int64_t kSeparation = 1 * kMs;  // frame B 1 ms after frame A
  constexpr std::int64_t kLatency = 7 * kMs;
  TriggerMatcher m(2, 100 * kMs, kSeparation);
  constexpr std::uint64_t kEvents = 6;
  for (std::uint64_t k = 0; k < kEvents; ++k) m.expect({k, Exposure::A, static_cast<std::int64_t>(k) * 200 * kMs});
  // The camera counts from 500: event k's frames are ids 500 + 2k (A) and 501 + 2k (B). Id 500
  // never arrives, so the caller's parity (sequence since the first frame received) is wrong.
  std::uint64_t sequence = 0;
  for (std::uint64_t k = 0; k < kEvents; ++k) {
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      if (k == 0 && e == Exposure::A) continue;  // lost entirely
      const std::uint64_t id = 500 + 2 * k + (e == Exposure::B ? 1 : 0);
      const std::int64_t time = kCameraClock + static_cast<std::int64_t>(k) * 200 * kMs + kLatency +
                                (e == Exposure::B ? kSeparation : 0);
      const Exposure parity = sequence++ % 2 == 0 ? Exposure::A : Exposure::B;
      const auto hit = m.match(id, time, parity);
      if (k == 0) continue;  // the lone first frame: nothing yet tells A from B
      ASSERT_TRUE(hit) << "event " << k;
      EXPECT_EQ(hit->event, k) << "id " << id;
      EXPECT_EQ(hit->exposure, e) << "id " << id;
    }
  }
  EXPECT_EQ(m.triggers_lost(), 0u);
}

// The camera's triggers move to another phase of its readout grid (two_triggers, see
// AravisCameraOptions::readout_ns): its offset grows by 35 ms. Relearnt, the next frames
// answer their own triggers; with the stale offset, a frame that also crossed a grid line
// (+40 ms) would pass for the next trigger's.
TEST(TriggerMatcher, RelearntOffsetsFollowAShiftedPhase) {
  TriggerMatcher m(1, 40 * kMs);
  expect_events(m, 3);  // A at 200k, B at 200k + 60 ms
  EXPECT_EQ(m.match(0, kCameraClock + 2 * kMs)->event, 0u);
  EXPECT_EQ(m.match(1, kCameraClock + 62 * kMs)->exposure, Exposure::B);
  m.relearn_offsets();
  // Event 1's frame A 35 ms later than before plus a 40 ms grid crossing: 77 ms after its
  // trigger, 17 ms after frame B's trigger plus the old offset.
  const auto a1 = m.match(2, kCameraClock + 200 * kMs + 77 * kMs);
  ASSERT_TRUE(a1);
  EXPECT_EQ(a1->event, 1u);
  EXPECT_EQ(a1->exposure, Exposure::A);
}

TEST(TriggerMatcher, OptionsAreChecked) {
  EXPECT_THROW(TriggerMatcher(3, kMs), Error);
  EXPECT_THROW(TriggerMatcher(1, 0), Error);
  EXPECT_THROW(TriggerMatcher(2, kMs, -1), Error);
}

}  // namespace
}  // namespace tomorig::acquisition
