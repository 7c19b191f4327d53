// Frame-straddling geometry: exact edges worked out by hand, and each infeasible case
// refused with a message naming the quantity, its value and the bound.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/core/error.h"
#include "tomorig/trigger/timing_plan.h"
#include "trigger_test_support.h"

namespace tomorig::trigger {
namespace {

using test::laser_rig;
using test::led_rig;

// The message of the bad_input error `inputs` must raise.
std::string refusal(const TimingInputs& inputs) {
  try {
    plan_timing(inputs);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    return e.what();
  }
  ADD_FAILURE() << "plan_timing accepted an infeasible plan";
  return {};
}

bool inside(const Pulse& inner, const Pulse& outer) {
  return outer.rise_ns <= inner.rise_ns && inner.fall_ns <= outer.fall_ns;
}

TEST(TimingPlan, LedRigEdgesAreExact) {
  // By hand: pulses centred at 0 and dt; the end of frame A goes midway between its bounds
  // (500 and 19500 ns), so A = [-10000, 10000); the camera fires 1 µs early, the LED 50 ns
  // early; everything then shifts so the camera edge (the earliest) is t = 0.
  const TimingPlan plan = plan_timing(led_rig());
  EXPECT_EQ(plan.period_ns, 100'000'000);
  EXPECT_EQ(plan.dt_ns, 100'000);
  EXPECT_EQ(plan.straddle_margin_ns, 9'500);
  EXPECT_EQ(plan.frame_a, (Pulse{1'000, 21'000}));
  EXPECT_EQ(plan.frame_b, (Pulse{21'120, 1'021'120}));
  EXPECT_EQ(plan.light_pulse_1, (Pulse{10'500, 11'500}));
  EXPECT_EQ(plan.light_pulse_2, (Pulse{110'500, 111'500}));
  ASSERT_EQ(plan.channels.size(), 2u);
  EXPECT_EQ(plan.find_channel("cam")->pulses, (std::vector<Pulse>{{0, 10'000}}));
  EXPECT_EQ(plan.find_channel("led1")->pulses, (std::vector<Pulse>{{10'450, 11'450}, {110'450, 111'450}}));
}

TEST(TimingPlan, PulsesLieInsideTheirExposures) {
  for (const TimingInputs& in : {led_rig(), laser_rig()}) {
    const TimingPlan plan = plan_timing(in);
    EXPECT_TRUE(inside(plan.light_pulse_1, plan.frame_a));
    EXPECT_TRUE(inside(plan.light_pulse_2, plan.frame_b));
    // The margin is real: sliding the pulses by it keeps them inside, one ns more does not.
    const std::int64_t m = plan.straddle_margin_ns;
    Pulse p1 = plan.light_pulse_1, p2 = plan.light_pulse_2;
    for (Pulse* p : {&p1, &p2}) p->rise_ns += m, p->fall_ns += m;
    EXPECT_TRUE(inside(p1, plan.frame_a) && inside(p2, plan.frame_b));
    for (Pulse* p : {&p1, &p2}) p->rise_ns -= 2 * m + 2, p->fall_ns -= 2 * m + 2;
    EXPECT_FALSE(inside(p1, plan.frame_a) && inside(p2, plan.frame_b));
  }
}

TEST(TimingPlan, LaserFlashLampsLeadTheirQSwitches) {
  const TimingPlan plan = plan_timing(laser_rig());
  // By hand: pulses [-5, 5) and [1995, 2005); end of frame A = 5 + (1875 - 5) / 2 = 940;
  // Q-switches 100 ns early, flash lamps 180 µs before them; flash lamp 1 is the earliest.
  EXPECT_EQ(plan.straddle_margin_ns, 935);
  EXPECT_EQ(plan.find_channel("fl1")->pulses, (std::vector<Pulse>{{0, 10'000}}));
  EXPECT_EQ(plan.find_channel("fl2")->pulses, (std::vector<Pulse>{{2'000, 12'000}}));
  EXPECT_EQ(plan.find_channel("qs1")->pulses, (std::vector<Pulse>{{180'000, 180'010}}));
  EXPECT_EQ(plan.find_channel("qs2")->pulses, (std::vector<Pulse>{{182'000, 182'010}}));
  EXPECT_EQ(plan.find_channel("cam")->pulses, (std::vector<Pulse>{{170'045, 180'045}}));
  EXPECT_EQ(plan.frame_a, (Pulse{171'045, 181'045}));
  EXPECT_EQ(plan.light_pulse_1, (Pulse{180'100, 180'110}));
  EXPECT_EQ(plan.light_pulse_2, (Pulse{182'100, 182'110}));
}

TEST(TimingPlan, DtIsCentreToCentreWhenWidthsDiffer) {
  TimingInputs in = laser_rig();
  in.light_sources[1].pulse_width_ns = 30;
  const TimingPlan plan = plan_timing(in);
  const auto centre2 = (plan.light_pulse_2.rise_ns + plan.light_pulse_2.fall_ns) / 2;
  const auto centre1 = (plan.light_pulse_1.rise_ns + plan.light_pulse_1.fall_ns) / 2;
  EXPECT_EQ(centre2 - centre1, in.dt_ns);
}

TEST(TimingPlan, PulseGeneratorFiresFirst) {
  TimingInputs in = led_rig();
  ChannelSpec gen;
  gen.name = "bnc575";
  gen.role = ChannelRole::pulse_generator;
  gen.delay_ns = 300;  // insertion delay of the generator
  gen.width_ns = 1'000'000;
  in.channels.push_back(gen);
  const TimingPlan plan = plan_timing(in);
  EXPECT_TRUE(plan.has_pulse_generator());
  EXPECT_EQ(plan.find_channel("bnc575")->pulses, (std::vector<Pulse>{{0, 1'000'000}}));
  EXPECT_EQ(plan.find_channel("cam")->pulses.front().rise_ns, 300);
}

TEST(TimingPlanInfeasible, DtShorterThanInterframeTime) {
  TimingInputs in = laser_rig();
  in.dt_ns = 100;  // gap between 10 ns pulses: 90 ns < interframe 120 ns
  const std::string m = refusal(in);
  EXPECT_NE(m.find("dt 0.1 us is too short"), std::string::npos) << m;
  EXPECT_NE(m.find("interframe time 0.12 us"), std::string::npos) << m;
  EXPECT_NE(m.find("dt must be >= 0.13 us"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, PulseWiderThanExposureA) {
  TimingInputs in = led_rig();
  in.camera.exposure_a_ns = 500;
  const std::string m = refusal(in);
  EXPECT_NE(m.find("light pulse 1 (1 us wide)"), std::string::npos) << m;
  EXPECT_NE(m.find("exposure A must be >= 1 us"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, PulseWiderThanExposureB) {
  TimingInputs in = led_rig();
  in.camera.exposure_b_ns = 800;
  const std::string m = refusal(in);
  EXPECT_NE(m.find("exposure B must be >= 1 us"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, DtLongerThanTheCameraWindow) {
  TimingInputs in = led_rig();
  in.dt_ns = 2'000'000;  // frames A + B last 1020.12 µs
  const std::string m = refusal(in);
  EXPECT_NE(m.find("dt 2000 us is too long for the camera"), std::string::npos) << m;
  EXPECT_NE(m.find("last 1020.12 us"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, EventLongerThanThePeriod) {
  TimingInputs in = led_rig();
  in.rate_hz = 2'000.0;  // 500 µs period, but frame B alone lasts 1 ms
  const std::string m = refusal(in);
  EXPECT_NE(m.find("longer than the period 500 us at 2000 Hz"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, ChannelPulsesOverlap) {
  TimingInputs in = led_rig();
  in.channels[1].width_ns = 150'000;  // electrical pulses wider than dt
  const std::string m = refusal(in);
  EXPECT_NE(m.find("channel 'led1'"), std::string::npos) << m;
  EXPECT_NE(m.find("before its pulse for frame A ends"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, BadInputsAreAllListed) {
  TimingInputs in = led_rig();
  in.rate_hz = 0.0;
  in.dt_ns = -5;
  in.channels[1].light_source = "nope";
  in.channels.push_back(in.channels[0]);  // duplicate "cam"
  const std::string m = refusal(in);
  EXPECT_NE(m.find("rate 0 Hz must be > 0"), std::string::npos) << m;
  EXPECT_NE(m.find("dt -0.005 us must be > 0"), std::string::npos) << m;
  EXPECT_NE(m.find("light source 'nope', which is not defined"), std::string::npos) << m;
  EXPECT_NE(m.find("channel 'cam' is defined twice"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, NeedsACameraAndBothPulses) {
  TimingInputs in = laser_rig();
  in.channels.erase(in.channels.begin());          // no camera
  in.channels.erase(in.channels.begin() + 2, in.channels.end());  // no head 2
  const std::string m = refusal(in);
  EXPECT_NE(m.find("no camera channel"), std::string::npos) << m;
  EXPECT_NE(m.find("no light channel makes pulse 2"), std::string::npos) << m;
}

TEST(TimingPlanInfeasible, FlashLampWithoutQSwitch) {
  TimingInputs in = laser_rig();
  in.channels.erase(in.channels.begin() + 2);  // qs1
  const std::string m = refusal(in);
  EXPECT_NE(m.find("flash-lamp channel 'fl1'"), std::string::npos) << m;
}

}  // namespace
}  // namespace tomorig::trigger

// Single-frame cameras triggered twice (frame_mode "two_triggers"): one trigger per frame,
// each frame centred on its pulse, frame B no earlier than the camera's readout after A.
namespace tomorig::trigger {
namespace {

TimingInputs two_trigger_rig(std::int64_t dt_ns, std::int64_t readout_ns) {
  TimingInputs in = test::led_rig();
  in.rate_hz = 5.0;
  in.dt_ns = dt_ns;
  in.camera.mode = FrameMode::two_triggers;
  in.camera.exposure_a_ns = 1'000'000;  // 1 ms per frame
  in.camera.readout_ns = readout_ns;
  return in;
}

TEST(TimingPlanTwoTriggers, EachFrameIsCentredOnItsPulseAndTheCameraIsTriggeredTwice) {
  // dt 60 ms, readout 40 ms: centred frames leave 59 ms between A's end and B's start.
  const TimingPlan plan = plan_timing(two_trigger_rig(60'000'000, 40'000'000));
  EXPECT_EQ(plan.camera.mode, FrameMode::two_triggers);
  EXPECT_TRUE(inside(plan.light_pulse_1, plan.frame_a));
  EXPECT_TRUE(inside(plan.light_pulse_2, plan.frame_b));
  EXPECT_EQ(plan.frame_a.width_ns(), 1'000'000);
  EXPECT_EQ(plan.frame_b.width_ns(), 1'000'000);  // one ExposureTime for both frames
  // Centred: pulse centre in the frame's middle, so B - A is dt exactly.
  EXPECT_EQ(plan.frame_separation_ns(), 60'000'000);
  EXPECT_EQ((plan.frame_a.rise_ns + plan.frame_a.fall_ns) / 2,
            (plan.light_pulse_1.rise_ns + plan.light_pulse_1.fall_ns) / 2);
  EXPECT_EQ(plan.straddle_margin_ns, (1'000'000 - 1'000) / 2);
  const ChannelTiming* cam = plan.find_channel("cam");
  ASSERT_NE(cam, nullptr);
  ASSERT_EQ(cam->pulses.size(), 2u);  // frame A's trigger and frame B's
  EXPECT_EQ(cam->pulses[1].rise_ns - cam->pulses[0].rise_ns, 60'000'000);
  EXPECT_EQ(cam->pulses[0].rise_ns, plan.frame_a.rise_ns - 1'000);  // early by the camera's delay
}

TEST(TimingPlanTwoTriggers, FramesMoveApartWhenTheReadoutNeedsIt) {
  // dt 40.5 ms, readout 40 ms: centred frames leave 39.5 ms, so A moves 0.25 ms earlier and B
  // 0.25 ms later; each pulse stays inside its frame with 0.2495 ms to spare.
  const TimingPlan plan = plan_timing(two_trigger_rig(40'500'000, 40'000'000));
  EXPECT_EQ(plan.frame_b.rise_ns - plan.frame_a.fall_ns, 40'000'000);
  EXPECT_TRUE(inside(plan.light_pulse_1, plan.frame_a));
  EXPECT_TRUE(inside(plan.light_pulse_2, plan.frame_b));
  EXPECT_EQ(plan.straddle_margin_ns, 249'500);
}

TEST(TimingPlanTwoTriggers, DtShorterThanTheReadoutIsRefusedAndSaysWhy) {
  const std::string msg = refusal(two_trigger_rig(30'000'000, 40'000'000));
  EXPECT_NE(msg.find("readout time 40000 us"), std::string::npos) << msg;
  EXPECT_NE(msg.find("two_triggers"), std::string::npos) << msg;
  EXPECT_NE(msg.find("dt must be >= 40001 us"), std::string::npos) << msg;  // readout + the 1 us pulse
}

TEST(TimingPlanTwoTriggers, ReadoutOfFrameBMustEndBeforeTheNextEvent) {
  TimingInputs in = two_trigger_rig(150'000'000, 80'000'000);  // B ends ~150 ms, + 80 ms readout > 200 ms
  const std::string msg = refusal(in);
  EXPECT_NE(msg.find("and its readout"), std::string::npos) << msg;
  EXPECT_NE(msg.find("longer than the period"), std::string::npos) << msg;
}

TEST(TimingPlanTwoTriggers, NeedsAReadoutTime) {
  const std::string msg = refusal(two_trigger_rig(60'000'000, 0));
  EXPECT_NE(msg.find("readout time"), std::string::npos) << msg;
}

TEST(TimingPlanTwoTriggers, HardwareDoubleFrameSeparationIsExposureAPlusInterframe) {
  const TimingPlan plan = plan_timing(test::led_rig());
  EXPECT_EQ(plan.frame_separation_ns(), 20'000 + 120);
}

}  // namespace
}  // namespace tomorig::trigger
