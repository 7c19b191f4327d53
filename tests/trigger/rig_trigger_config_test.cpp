// The configured trigger keys reach the timing plan and the device: camera timing, light
// sources with kinds and safety limits, channel roles, delays and widths, GPIO resolution. A
// configured limit must change what a device arms, in both directions.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "cli_runner.h"
#include "tomorig/core/error.h"
#include "tomorig/trigger/rig_trigger.h"

namespace tomorig::trigger {
namespace {

// A one-camera simulated rig whose [trigger] table (after `backend`) is `body`.
config::RigConfig rig_with(const std::string& body, const std::string& backend = "simulated") {
  return config::parse_rig_config("[[cameras]]\nid = \"cam0\"\nbackend = \"simulated\"\n"
                                  "[cameras.roi]\nwidth = 64\nheight = 64\n"
                                  "[trigger]\nbackend = \"" + backend + "\"\n" + body);
}

// One LED (pulse `width_us`, extra source keys `limits`) making both pulses, one camera.
std::string led_rig(const std::string& width_us, const std::string& limits = "", const std::string& rate = "10") {
  return "rate_hz = " + rate + "\n"
         "[[trigger.light_sources]]\nname = \"led1\"\nkind = \"led\"\npulse_width_us = " + width_us + "\n" + limits +
         "[[trigger.channels]]\nname = \"led\"\nrole = \"light\"\nlight_source = \"led1\"\n"
         "[[trigger.channels]]\nname = \"cams\"\nrole = \"camera\"\n";
}

// A laser (10 ns, no flash lamp channel) at `rate` Hz with extra source keys `limits`.
std::string laser_rig(const std::string& rate, const std::string& limits = "") {
  return "rate_hz = " + rate + "\n"
         "[[trigger.light_sources]]\nname = \"yag\"\nkind = \"laser\"\n" + limits +
         "[[trigger.channels]]\nname = \"qswitch\"\nrole = \"light\"\nlight_source = \"yag\"\n"
         "[[trigger.channels]]\nname = \"cams\"\nrole = \"camera\"\n";
}

// The refusal of plan_and_check(), or "" when it accepts.
std::string refusal(const RigTrigger& t) {
  try {
    plan_and_check(t);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    return e.what();
  }
  return {};
}

// The device's own verdict on the plan (built without any check): "" when it arms.
std::string arm_refusal(const RigTrigger& t) {
  const TimingPlan plan = plan_timing(t.inputs);
  auto device = make_trigger_device(t, Pacing::as_fast_as_consumed);
  try {
    device->arm(plan);
  } catch (const Error& e) {
    return e.what();
  }
  return {};
}

void expect_has(const std::string& message, std::initializer_list<const char*> parts) {
  for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << "missing '" << part << "' in: " << message;
}

TEST(RigTriggerConfig, MapsEveryConfiguredInput) {
  const RigTrigger t = rig_trigger(rig_with(R"(dt_us = 2.0
gpio_resolution_us = 500
[trigger.camera]
exposure_a_us = 10
interframe_us = 0.2
exposure_b_us = 2000
[[trigger.light_sources]]
name = "head1"
kind = "laser"
flashlamp_lead_us = 180
max_rate_hz = 15
[[trigger.light_sources]]
name = "led1"
kind = "led"
pulse_width_us = 0.4
max_pulse_width_us = 1.5
max_duty_cycle = 0.0005
[[trigger.channels]]
name = "lamp1"
role = "flashlamp"
light_source = "head1"
pulses = "first"
width_us = 10
[[trigger.channels]]
name = "q1"
role = "light"
light_source = "head1"
pulses = "first"
delay_us = 0.1
[[trigger.channels]]
name = "led"
role = "light"
light_source = "led1"
pulses = "second"
[[trigger.channels]]
name = "cams"
role = "camera"
delay_us = 1.5
[[trigger.channels]]
name = "gen"
role = "pulse_generator"
)"));
  EXPECT_EQ(t.inputs.camera.exposure_a_ns, 10'000);
  EXPECT_EQ(t.inputs.camera.interframe_ns, 200);
  EXPECT_EQ(t.inputs.camera.exposure_b_ns, 2'000'000);
  EXPECT_EQ(t.gpio.resolution_ns, 500'000);

  ASSERT_EQ(t.inputs.light_sources.size(), 2u);
  const LightSource& head = t.inputs.light_sources[0];
  EXPECT_EQ(head.kind, LightSourceKind::laser);
  EXPECT_EQ(head.pulse_width_ns, 10);  // trigger.pulse_width_us, the default
  EXPECT_EQ(head.flashlamp_lead_ns, 180'000);
  EXPECT_EQ(head.limits.max_rate_hz, 15.0);
  EXPECT_FALSE(head.limits.max_pulse_width_ns.has_value());  // the laser default applies
  const LightSource& led = t.inputs.light_sources[1];
  EXPECT_EQ(led.kind, LightSourceKind::led);
  EXPECT_EQ(led.pulse_width_ns, 400);
  EXPECT_EQ(led.limits.max_pulse_width_ns, 1'500);
  EXPECT_EQ(led.limits.max_duty_cycle, 0.0005);

  ASSERT_EQ(t.inputs.channels.size(), 5u);
  const auto& ch = t.inputs.channels;
  EXPECT_EQ(ch[0].role, ChannelRole::flashlamp);
  EXPECT_EQ(ch[0].light_source, "head1");
  EXPECT_EQ(ch[0].pulses, PulseSelect::first);
  EXPECT_EQ(ch[0].width_ns, 10'000);
  EXPECT_EQ(ch[1].delay_ns, 100);
  EXPECT_EQ(ch[2].pulses, PulseSelect::second);
  EXPECT_EQ(ch[3].role, ChannelRole::camera);
  EXPECT_EQ(ch[3].delay_ns, 1'500);
  EXPECT_EQ(ch[4].role, ChannelRole::pulse_generator);

  // The configured geometry reaches the plan: the camera fires early by its latency, the flash
  // lamp leads its Q-switch by the configured lead.
  const TimingPlan plan = plan_and_check(t);
  EXPECT_EQ(plan.frame_a.width_ns(), 10'000);
  EXPECT_EQ(plan.frame_b.rise_ns - plan.frame_a.fall_ns, 200);
  EXPECT_EQ(plan.find_channel("cams")->pulses.at(0).rise_ns, plan.frame_a.rise_ns - 1'500);
  EXPECT_EQ(plan.find_channel("q1")->pulses.at(0).rise_ns - plan.find_channel("lamp1")->pulses.at(0).rise_ns, 180'000);
  EXPECT_EQ(plan.find_channel("led")->pulses.size(), 1u);  // pulses = "second"
}

TEST(RigTriggerConfig, ConfiguredCameraTimingDecidesFeasibility) {
  // dt 1 µs leaves 0.99 µs between two 10 ns pulses: enough for the 0.12 µs default
  // interframe, not for a configured 2 µs.
  EXPECT_EQ(refusal(rig_trigger(rig_with("dt_us = 1.0\n"))), "");
  expect_has(refusal(rig_trigger(rig_with("dt_us = 1.0\n[trigger.camera]\ninterframe_us = 2\n"))),
             {"dt 1 us is too short for the camera", "interframe time 2 us"});
}

TEST(RigTriggerConfig, ConfiguredPulseWidthLimitRefusesWhatTheDefaultAllows) {
  // 1.5 µs LED pulses: within the built-in LED limit of 2 µs ...
  const RigTrigger by_default = rig_trigger(rig_with(led_rig("1.5")));
  EXPECT_EQ(refusal(by_default), "");
  EXPECT_EQ(arm_refusal(by_default), "");
  // ... beyond a configured 1 µs, in the planner and in the device itself.
  const RigTrigger limited = rig_trigger(rig_with(led_rig("1.5", "max_pulse_width_us = 1.0\n")));
  expect_has(refusal(limited), {"max_pulse_width", "'led1' (led)", "1.5 us", "1 us (configured)"});
  expect_has(arm_refusal(limited), {"max_pulse_width", "'led1'", "configured"});
}

TEST(RigTriggerConfig, ConfiguredPulseWidthLimitAllowsWhatTheDefaultRefuses) {
  // 4 µs LED pulses: beyond the built-in 2 µs, within a configured 5 µs.
  expect_has(arm_refusal(rig_trigger(rig_with(led_rig("4")))), {"max_pulse_width", "built-in led default"});
  const RigTrigger allowed = rig_trigger(rig_with(led_rig("4", "max_pulse_width_us = 5\n")));
  EXPECT_EQ(refusal(allowed), "");
  EXPECT_EQ(arm_refusal(allowed), "");
}

TEST(RigTriggerConfig, ConfiguredRateLimitWorksBothWays) {
  // A laser at 20 Hz: inside the built-in 30 Hz, outside a head rated for 15 Hz.
  EXPECT_EQ(arm_refusal(rig_trigger(rig_with(laser_rig("20")))), "");
  expect_has(arm_refusal(rig_trigger(rig_with(laser_rig("20", "max_rate_hz = 15\n")))),
             {"max_rate_hz", "'yag' (laser)", "15 Hz (configured)"});
  // At 40 Hz: refused by default, allowed for a head rated for 50 Hz.
  expect_has(arm_refusal(rig_trigger(rig_with(laser_rig("40")))), {"max_rate_hz", "built-in laser default"});
  EXPECT_EQ(arm_refusal(rig_trigger(rig_with(laser_rig("40", "max_rate_hz = 50\n")))), "");
}

TEST(RigTriggerConfig, ConfiguredDutyCycleLimitRefuses) {
  // Two 1.5 µs pulses per 100 ms: duty 3e-5, inside the default 1e-3, outside 1e-5.
  EXPECT_EQ(arm_refusal(rig_trigger(rig_with(led_rig("1.5")))), "");
  expect_has(arm_refusal(rig_trigger(rig_with(led_rig("1.5", "max_duty_cycle = 0.00001\n")))),
             {"max_duty_cycle", "'led1'", "configured"});
}

TEST(RigTriggerConfig, SourceWithoutKindGetsTheStrictestLimits) {
  // 40 Hz would suit an LED (built-in 1000 Hz), but a source of no stated kind gets the
  // strictest rate limit of every kind: the laser's 30 Hz.
  const std::string rig = "rate_hz = 40\n[[trigger.light_sources]]\nname = \"s\"\n"
                          "[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\nlight_source = \"s\"\n"
                          "[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n";
  expect_has(arm_refusal(rig_trigger(rig_with(rig))), {"max_rate_hz", "'s' (unknown)", "built-in unknown default"});
}

TEST(RigTriggerConfig, GpioWithAPulseGeneratorPlansMicrosecondDt) {
  const RigTrigger t = rig_trigger(rig_with(
      "dt_us = 2.0\n[[trigger.light_sources]]\nname = \"yag\"\nkind = \"laser\"\n"
      "[[trigger.channels]]\nname = \"gen\"\nrole = \"pulse_generator\"\nchip = \"gpiochip0\"\nline = 4\n"
      "[[trigger.channels]]\nname = \"q\"\nrole = \"light\"\nlight_source = \"yag\"\n"
      "[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n",
      "gpio"));
  const TimingPlan plan = plan_and_check(t);
  // The generator's trigger input is a GPIO output: as wide as the GPIO resolution.
  EXPECT_EQ(plan.find_channel("gen")->pulses.at(0).width_ns(), 1'000'000);
  EXPECT_EQ(t.capabilities().resolution_ns, 1'000'000);
  EXPECT_EQ(rig_trigger(rig_with("gpio_resolution_us = 250\n[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n"
                                 "chip = \"gpiochip0\"\nline = 1\n",
                                 "gpio"))
                .capabilities()
                .resolution_ns,
            250'000);
}

TEST(RigTriggerConfig, CliRefusesAConfiguredLimitNamingIt) {
  if (!testing::tomorig_built()) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
  testing::TempDir dir;
  const auto path = dir / "led.toml";
  std::ofstream(path) << "[[cameras]]\nid = \"cam0\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 64\nheight = 64\n"
                         "[trigger]\nbackend = \"simulated\"\n"
                      << led_rig("1.5", "max_pulse_width_us = 1.0\n");
  const testing::CliResult r = testing::run_tomorig("trigger plan --config '" + path.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  expect_has(r.err, {"max_pulse_width", "led1", "configured"});
}

}  // namespace
}  // namespace tomorig::trigger
