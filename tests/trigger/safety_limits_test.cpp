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

}  // namespace
}  // namespace tomorig::trigger
