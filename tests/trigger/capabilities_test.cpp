// Device capabilities: resolution, jitter, channel count and minimum pulse, each named.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/trigger/capabilities.h"
#include "tomorig/trigger/gpio_device.h"
#include "tomorig/trigger/simulated_device.h"
#include "trigger_test_support.h"

namespace tomorig::trigger {
namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

TEST(Capabilities, SimulatedDeviceTakesTypicalRigs) {
  EXPECT_TRUE(capability_problems(plan_timing(test::led_rig()), simulated_capabilities({})).empty());
  EXPECT_TRUE(capability_problems(plan_timing(test::laser_rig()), simulated_capabilities({})).empty());
}

TEST(Capabilities, JitterMustFitTheStraddleMargin) {
  SimulatedTriggerOptions options;
  options.jitter_ns = 400.0;  // 3 sigma = 1.2 µs > the laser rig's 0.935 µs margin
  const auto problems = capability_problems(plan_timing(test::laser_rig()), simulated_capabilities(options));
  ASSERT_EQ(problems.size(), 1u) << joined(problems);
  EXPECT_NE(problems[0].find("straddle margin 0.935 us"), std::string::npos) << problems[0];
  EXPECT_NE(problems[0].find("jitter of 0.4 us"), std::string::npos) << problems[0];
}

TEST(Capabilities, ChannelCount) {
  SimulatedTriggerOptions options;
  options.max_channels = 4;
  const auto problems = capability_problems(plan_timing(test::laser_rig()), simulated_capabilities(options));
  ASSERT_EQ(problems.size(), 1u) << joined(problems);
  EXPECT_NE(problems[0].find("needs 5 output channels, the simulated device has 4"), std::string::npos) << problems[0];
}

TEST(Capabilities, GpioResolutionAndMinimumPulse) {
  TimingInputs in = test::led_rig();
  for (auto& c : in.channels) c.chip = "gpiochip0", c.line = c.role == ChannelRole::camera ? 1 : 2;
  const auto problems = capability_problems(plan_timing(in), gpio_capabilities({}));
  const std::string all = joined(problems);
  EXPECT_NE(all.find("dt 100 us is below the gpio device's time resolution of 1000 us"), std::string::npos) << all;
  EXPECT_NE(all.find("channel 'led1': pulse width 1 us is below the gpio device's minimum pulse of 1000 us"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("channel 'cam': pulse width 10 us"), std::string::npos) << all;
}

TEST(Capabilities, GpioNeedsWiringOrAPulseGenerator) {
  const auto problems = capability_problems(plan_timing(test::led_rig()), gpio_capabilities({}));
  const std::string all = joined(problems);
  EXPECT_NE(all.find("channel 'cam' has no gpio output (chip and line) and no pulse_generator channel"),
            std::string::npos)
      << all;
}

}  // namespace
}  // namespace tomorig::trigger
