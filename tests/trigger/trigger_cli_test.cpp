// End to end: `tomorig trigger plan` as an operator runs it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"

namespace tomorig::testing {
namespace {

// A one-camera rig whose [trigger] table is `trigger_toml`.
std::string rig_with_trigger(const std::string& trigger_toml) {
  return "name = \"trigger test rig\"\n"
         "[[cameras]]\nid = \"cam0\"\nbackend = \"simulated\"\n"
         "[cameras.roi]\nwidth = 64\nheight = 64\n" +
         trigger_toml;
}

std::string write(const TempDir& dir, const std::string& name, const std::string& text) {
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// A tree built without the binary (TOMORIG_TEST_CLI=OFF, the CI sanitizer tree) skips these.
class TriggerCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
  }
};

TEST_F(TriggerCli, PlanOnTheDefaultRigPrintsEveryChannel) {
  const CliResult r = run_tomorig("trigger plan");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* text : {"laser", "cameras", "frame A", "frame B", "pulse 1", "dt 100 us", "feasible"})
    EXPECT_NE(r.out.find(text), std::string::npos) << text << " in:\n" << r.out;
}

TEST_F(TriggerCli, JsonParsesAndHoldsThePlan) {
  const CliResult r = run_tomorig("trigger plan --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("dt_us").get<double>(), 100.0);
  EXPECT_EQ(j.at("rate_hz").get<double>(), 10.0);
  ASSERT_EQ(j.at("channels").size(), 2u);
  // Pulse 1 inside frame A, pulse 2 inside frame B, as printed.
  const auto& a = j.at("frame_a");
  const auto& p1 = j.at("light_pulse_1");
  EXPECT_LE(a.at("rise_us").get<double>(), p1.at("rise_us").get<double>());
  EXPECT_LE(p1.at("fall_us").get<double>(), a.at("fall_us").get<double>());
  EXPECT_EQ(j.at("device").at("name"), "simulated");
}

TEST_F(TriggerCli, GpioRigWithMicrosecondDtExits2) {
  TempDir dir;
  const std::string rig = write(dir, "gpio.toml", rig_with_trigger(R"(
[trigger]
backend = "gpio"
rate_hz = 10.0
dt_us = 100.0
[[trigger.channels]]
name = "laser"
role = "light"
chip = "gpiochip0"
line = 17
[[trigger.channels]]
name = "cam"
role = "camera"
chip = "gpiochip0"
line = 18
)"));
  const CliResult r = run_tomorig("trigger plan --config '" + rig + "'");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.err.find("dt 100 us is below the gpio device's time resolution of 1000 us"), std::string::npos) << r.err;
}

TEST_F(TriggerCli, InfeasibleTimingExits2) {
  TempDir dir;
  // 5 kHz: a 200 µs period cannot hold the camera's 1 ms frame B.
  const std::string rig = write(dir, "fast.toml", rig_with_trigger("[trigger]\nbackend = \"simulated\"\nrate_hz = 5000.0\n"));
  const CliResult r = run_tomorig("trigger plan --config '" + rig + "' --json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("longer than the period 200 us"), std::string::npos) << r.err;
}

// The issue's LED split over two channels: 1000 Hz, 0.6 µs pulses, one channel per pulse, on
// together 0.12 % of the time against the LED's 0.1 %. Neither `trigger plan` nor `run` may
// accept it.
const char* kSplitLed = R"(
[trigger]
backend = "simulated"
rate_hz = 1000.0
dt_us = 100.0
[trigger.camera]
exposure_a_us = 20.0
exposure_b_us = 500.0
[[trigger.light_sources]]
name = "led1"
kind = "led"
pulse_width_us = 0.6
max_rate_hz = 100000.0
[[trigger.channels]]
name = "cam"
role = "camera"
[[trigger.channels]]
name = "led_p1"
role = "light"
light_source = "led1"
pulses = "first"
[[trigger.channels]]
name = "led_p2"
role = "light"
light_source = "led1"
pulses = "second"
)";

TEST_F(TriggerCli, OneLedSplitOverTwoChannelsIsRefusedByPlanAndRun) {
  TempDir dir;
  const std::string rig = write(dir, "split.toml", rig_with_trigger(kSplitLed));
  const CliResult plan = run_tomorig("trigger plan --config '" + rig + "'");
  EXPECT_EQ(plan.exit_code, 2) << plan.out;
  EXPECT_EQ(plan.out.find("within the light-source safety limits"), std::string::npos) << plan.out;
  EXPECT_NE(plan.err.find("max_duty_cycle"), std::string::npos) << plan.err;
  EXPECT_NE(plan.err.find("0.12 %"), std::string::npos) << plan.err;
  EXPECT_NE(plan.err.find("'led_p1', 'led_p2' together"), std::string::npos) << plan.err;

  const auto out = (dir / "s.h5").string();
  const CliResult run = run_tomorig("run --config '" + rig + "' --sets 2 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 2) << run.out << run.err;
  EXPECT_NE(run.err.find("max_duty_cycle"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out + ".partial"));
}

TEST_F(TriggerCli, MissingConfigExits2) {
  const CliResult r = run_tomorig("trigger plan --config /nonexistent/rig.toml");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent/rig.toml"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tomorig::testing
