// Safety limits are enforced by TriggerDevice::arm(): every limit refuses with its name, the
// light source and the value, whoever built the plan.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/core/error.h"
#include "tomorig/trigger/safety_limits.h"
#include "tomorig/trigger/simulated_device.h"
#include "trigger_test_support.h"

namespace tomorig::trigger {
namespace {

using test::laser_rig;
using test::led_rig;

// The message with which a simulated device (safety table `sources`) refuses `plan`.
std::string arm_refusal(const TimingPlan& plan, const std::vector<LightSource>& sources) {
  auto device = make_simulated_device({}, sources);
  try {
    device->arm(plan);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_FALSE(device->armed());
    return e.what();
  }
  ADD_FAILURE() << "the device armed a plan beyond a safety limit";
  return {};
}

void expect_has(const std::string& message, std::initializer_list<const char*> parts) {
  for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << "missing '" << part << "' in: " << message;
}

TEST(SafetyDefaults, ConservativePerKind) {
  const ResolvedLimits led = default_limits(LightSourceKind::led);
  EXPECT_EQ(led.max_pulse_width_ns, 2'000);  // an overdriven LED: a few µs at most
  EXPECT_DOUBLE_EQ(led.max_duty_cycle, 1e-3);
  EXPECT_DOUBLE_EQ(led.max_rate_hz, 1000.0);
  const ResolvedLimits laser = default_limits(LightSourceKind::laser);
  EXPECT_EQ(laser.max_pulse_width_ns, 20'000);
  EXPECT_DOUBLE_EQ(laser.max_rate_hz, 30.0);
  const ResolvedLimits unknown = default_limits(LightSourceKind::unknown);
  EXPECT_EQ(unknown.max_pulse_width_ns, 2'000);
  EXPECT_DOUBLE_EQ(unknown.max_duty_cycle, 1e-3);
  EXPECT_DOUBLE_EQ(unknown.max_rate_hz, 30.0);
}

TEST(SafetyDefaults, ConfiguredFieldsOverrideOnlyThemselves) {
  LightSource s{"led1", LightSourceKind::led, 400, 0, {}};
  s.limits.max_pulse_width_ns = 5'000;
  const ResolvedLimits r = resolve_limits(s);
  EXPECT_EQ(r.max_pulse_width_ns, 5'000);
  EXPECT_DOUBLE_EQ(r.max_duty_cycle, 1e-3);
  EXPECT_DOUBLE_EQ(r.max_rate_hz, 1000.0);
}

TEST(SafetyLimits, TypicalRigsArm) {
  for (const TimingInputs& in : {led_rig(), laser_rig()}) {
    auto device = make_simulated_device({}, in.light_sources);
    EXPECT_NO_THROW(device->arm(plan_timing(in)));
    EXPECT_TRUE(device->armed());
  }
}

TEST(SafetyLimits, MaxPulseWidthRefusedFromAPlannedRig) {
  // plan_timing() does not judge safety; the device does.
  TimingInputs in = led_rig();
  in.light_sources[0].pulse_width_ns = 5'000;
  const std::string m = arm_refusal(plan_timing(in), in.light_sources);
  expect_has(m, {"max_pulse_width", "light source 'led1' (led)", "5 us", "limit of 2 us", "built-in led default"});
}

TEST(SafetyLimits, MaxPulseWidthRefusedFromAHandBuiltPlan) {
  TimingPlan plan;  // no plan_timing(), no validation
  plan.rate_hz = 10.0;
  plan.period_ns = 100'000'000;
  plan.dt_ns = 100'000;
  ChannelTiming led;
  led.spec.name = "led1";
  led.spec.role = ChannelRole::light;
  led.spec.light_source = "led1";
  led.pulses = {{0, 50'000}};
  plan.channels = {led};
  // The plan even claims a generous limit; the device's table is what counts.
  LightSource claimed{"led1", LightSourceKind::led, 50'000, 0, {}};
  claimed.limits.max_pulse_width_ns = 1'000'000;
  plan.light_sources = {claimed};
  const std::string m = arm_refusal(plan, {{"led1", LightSourceKind::led, 400, 0, {}}});
  expect_has(m, {"max_pulse_width", "'led1'", "50 us"});
}

TEST(SafetyLimits, MaxDutyCycle) {
  TimingInputs in = led_rig();
  in.rate_hz = 1'000.0;
  in.camera.exposure_b_ns = 500'000;
  in.light_sources[0].limits.max_rate_hz = 1e6;  // isolate the duty-cycle limit
  // 2 x 1 µs per 1 ms = 0.2 % > 0.1 %
  const std::string m = arm_refusal(plan_timing(in), in.light_sources);
  expect_has(m, {"max_duty_cycle", "light source 'led1' (led)", "0.2 %", "limit of 0.1 %"});
}

TEST(SafetyLimits, MaxRate) {
  TimingInputs in = laser_rig();
  in.rate_hz = 50.0;  // flash-lamp heads take 30 Hz
  in.camera.exposure_b_ns = 10'000'000;
  const std::string m = arm_refusal(plan_timing(in), in.light_sources);
  expect_has(m, {"max_rate_hz", "light source 'head1' (laser)", "fired at 50 Hz", "limit of 30 Hz"});
}

TEST(SafetyLimits, ConfiguredLimitAllowsWhatTheDefaultRefuses) {
  TimingInputs in = led_rig();
  in.light_sources[0].pulse_width_ns = 5'000;
  in.light_sources[0].limits.max_pulse_width_ns = 10'000;  // an LED rated for 10 µs
  auto device = make_simulated_device({}, in.light_sources);
  EXPECT_NO_THROW(device->arm(plan_timing(in)));
}

TEST(SafetyLimits, SourceMissingFromTheDeviceTableGetsTheStrictestDefaults) {
  TimingInputs in = led_rig();
  in.rate_hz = 40.0;  // fine for an LED (1000 Hz), not for a source of unknown kind (30 Hz)
  const TimingPlan plan = plan_timing(in);
  auto device = make_simulated_device({}, in.light_sources);
  EXPECT_NO_THROW(device->arm(plan));
  const std::string m = arm_refusal(plan, {});
  expect_has(m, {"max_rate_hz", "'led1'", "not in the device's light-source table", "fired at 40 Hz"});
}

TEST(SafetyLimits, MalformedPlanRefused) {
  TimingPlan plan = plan_timing(led_rig());
  plan.channels[1].pulses[1].fall_ns = plan.period_ns + 1;
  expect_has(arm_refusal(plan, led_rig().light_sources), {"malformed", "led1"});
  plan.period_ns = 0;
  expect_has(arm_refusal(plan, led_rig().light_sources), {"period 0 ns"});
}


// ---- One light source driven by several channels: the limits hold for the source. ----

// The LED: 1000 Hz, 0.6 µs pulses, pulse 1 and pulse 2 → 1.2 µs per 1 ms = 0.12 % of the
// time against a 0.1 % limit. `split` says which channels make which pulse.
TimingInputs fast_led(std::vector<PulseSelect> split) {
  TimingInputs in = led_rig();
  in.rate_hz = 1'000.0;
  in.camera.exposure_b_ns = 500'000;
  in.light_sources[0].pulse_width_ns = 600;
  in.light_sources[0].limits.max_rate_hz = 1e6;  // isolate the duty-cycle limit
  const ChannelSpec base = in.channels[1];
  in.channels.resize(1);
  for (std::size_t i = 0; i < split.size(); ++i) {
    ChannelSpec c = base;
    c.name = "led1_ch" + std::to_string(i);
    c.pulses = split[i];
    in.channels.push_back(c);
  }
  return in;
}

TEST(SafetyPerSource, DutyCycleSumsEveryChannelOfTheSource) {
  using P = PulseSelect;
  // Every way to make pulses 1 and 2 of one LED with one, two or three channels.
  const std::vector<std::vector<P>> splits = {
      {P::both},          {P::first, P::second}, {P::second, P::first},  {P::both, P::first},
      {P::both, P::second}, {P::first, P::first, P::second}, {P::first, P::second, P::second},
      {P::both, P::both}};
  for (const auto& split : splits) {
    const TimingInputs in = fast_led(split);
    const std::string m = arm_refusal(plan_timing(in), in.light_sources);
    expect_has(m, {"max_duty_cycle", "light source 'led1' (led)", "0.12 %", "limit of 0.1 %"});
    if (split.size() > 1) expect_has(m, {"channels 'led1_ch0', 'led1_ch1'", "together"});
  }
}

TEST(SafetyPerSource, ASplitSourceWithinTheLimitArms) {
  // The same split LED at 800 Hz is on 1.2 µs per 1.25 ms = 0.096 %: the sum, not the number of
  // channels, decides.
  for (const auto& split : {std::vector<PulseSelect>{PulseSelect::first, PulseSelect::second},
                            {PulseSelect::both, PulseSelect::first}}) {
    TimingInputs in = fast_led(split);
    in.rate_hz = 800.0;
    auto device = make_simulated_device({}, in.light_sources);
    EXPECT_NO_THROW(device->arm(plan_timing(in)));
  }
}

TEST(SafetyPerSource, TwoSourcesEachWithinTheirLimitArm) {
  // Two LEDs, one per pulse: each is on 0.06 % of the time, and each is its own source.
  TimingInputs in = fast_led({PulseSelect::first, PulseSelect::second});
  in.light_sources.push_back(in.light_sources[0]);
  in.light_sources[1].name = "led2";
  in.channels[2].light_source = "led2";
  auto device = make_simulated_device({}, in.light_sources);
  EXPECT_NO_THROW(device->arm(plan_timing(in)));
}

// A hand-built plan: `led` pulses given per channel, all on source led1, period 1 ms.
TimingPlan hand_plan(const std::vector<std::vector<Pulse>>& per_channel) {
  TimingPlan plan;
  plan.rate_hz = 1'000.0;
  plan.period_ns = 1'000'000;
  plan.dt_ns = 100'000;
  for (std::size_t i = 0; i < per_channel.size(); ++i) {
    ChannelTiming ch;
    ch.spec.name = "ch" + std::to_string(i);
    ch.spec.role = ChannelRole::light;
    ch.spec.light_source = "led1";
    ch.pulses = per_channel[i];
    plan.channels.push_back(ch);
  }
  return plan;
}

const std::vector<LightSource> kOneLed = [] {
  LightSource s{"led1", LightSourceKind::led, 1'000, 0, {}};
  s.limits.max_duty_cycle = 1.0;  // isolate the pulse-width limit
  s.limits.max_rate_hz = 1e6;
  return std::vector<LightSource>{s};
}();

TEST(SafetyPerSource, TouchingPulsesOfTwoChannelsAreOnePulse) {
  // 1.5 µs + 1.5 µs back to back on two channels: the LED sees one 3 µs pulse (limit 2 µs).
  const std::string m = arm_refusal(hand_plan({{{10'000, 11'500}}, {{11'500, 13'000}}}), kOneLed);
  expect_has(m, {"max_pulse_width", "'led1'", "3 us", "channels 'ch0', 'ch1' together"});
}

TEST(SafetyPerSource, OverlappingPulsesOfTwoChannelsAreOnePulse) {
  const std::string m = arm_refusal(hand_plan({{{10'000, 11'500}}, {{11'000, 12'200}}}), kOneLed);
  expect_has(m, {"max_pulse_width", "2.2 us"});
}

TEST(SafetyPerSource, APulseAcrossThePeriodBoundaryIsOnePulse) {
  // The end of one period and the start of the next: 1.5 µs + 1.5 µs, continuous in time.
  const std::string m = arm_refusal(hand_plan({{{998'500, 1'000'000}}, {{0, 1'500}}}), kOneLed);
  expect_has(m, {"max_pulse_width", "3 us"});
}

TEST(SafetyPerSource, OverlapIsNotCountedTwiceInTheDutyCycle) {
  // Two channels firing the same 1 µs pulse: the LED is on 1 µs per period, not 2.
  LightSource s{"led1", LightSourceKind::led, 1'000, 0, {}};
  s.limits.max_rate_hz = 1e6;
  s.limits.max_duty_cycle = 1.5e-3;  // 0.1 % would pass, 0.2 % would not
  auto device = make_simulated_device({}, {s});
  EXPECT_NO_THROW(device->arm(hand_plan({{{10'000, 11'000}}, {{10'000, 11'000}}})));
  // ... while two separate 1 µs pulses are 0.2 %.
  EXPECT_NE(arm_refusal(hand_plan({{{10'000, 11'000}}, {{20'000, 21'000}}}), {s}).find("max_duty_cycle"),
            std::string::npos);
}

TEST(SafetyPerSource, RateCountsFlashLampAndLightChannelsOfOneHead) {
  // A flash lamp alone is enough to count the head as fired in an event.
  TimingInputs in = laser_rig();
  in.rate_hz = 50.0;
  in.camera.exposure_b_ns = 10'000'000;
  TimingPlan plan = plan_timing(in);
  for (auto& ch : plan.channels)
    if (ch.spec.role == ChannelRole::light) ch.pulses.clear();
  const std::string m = arm_refusal(plan, in.light_sources);
  expect_has(m, {"max_rate_hz", "light source 'head1' (laser)", "fired at 50 Hz"});
}

}  // namespace
}  // namespace tomorig::trigger
