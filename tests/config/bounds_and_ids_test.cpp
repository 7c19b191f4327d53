// Issue 14, defects 5 and 7 in the rig file: every time is bounded before any arithmetic (9.3e15 us
// wrapped in the trigger's llround into "width -9223372036854776 us"), image sides are bounded,
// and camera ids follow the one id rule (core/camera_id.h): `a/b`, `..`, NUL and escape
// sequences are refused by `tomorig config check`, not first by `run`.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "config_test_support.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config {
namespace {
using test_support::dump;

const std::string kCamera = "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 64\nheight = 48\n\n";
const std::string kSim = "[trigger]\nbackend = \"simulated\"\n";
const std::string kChannel = kSim +
                             "[[trigger.light_sources]]\nname = \"laser\"\nkind = \"laser\"\n"
                             "[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n";

// The issue for `key`, whose message must contain `text`.
void expect_issue(const std::string& doc, const std::string& key, const std::string& text) {
  const auto issues = check_rig_config(doc, "rig.toml");
  const bool found = std::any_of(issues.begin(), issues.end(), [&](const ConfigIssue& i) {
    return i.key == key && i.message.find(text) != std::string::npos;
  });
  EXPECT_TRUE(found) << "no issue for " << key << " containing \"" << text << "\"; got:\n" << dump(issues) << "in:\n"
                     << doc;
}

struct BoundCase {
  const char* name;
  std::string doc;
  const char* key;
  const char* text;
};

class TimeBounds : public ::testing::TestWithParam<BoundCase> {};

TEST_P(TimeBounds, HugeTimesAreRefusedBeforeAnyArithmetic) {
  expect_issue(GetParam().doc, GetParam().key, GetParam().text);
}

constexpr const char* kCeiling = "must be <= 1e+09 (1000 s, the longest time a rig file may give)";

INSTANTIATE_TEST_SUITE_P(
    Config, TimeBounds,
    ::testing::Values(
        BoundCase{"dt", kCamera + kSim + "rate_hz = 0.001\ndt_us = 9.3e15\n", "trigger.dt_us", kCeiling},
        BoundCase{"pulse_width", kCamera + kSim + "pulse_width_us = 9.3e15\n", "trigger.pulse_width_us", kCeiling},
        BoundCase{"jitter", kCamera + kSim + "jitter_ns = 1e19\n", "trigger.jitter_ns", "must be <= 1e+12"},
        BoundCase{"gpio_resolution", kCamera + kSim + "gpio_resolution_us = 1e16\n", "trigger.gpio_resolution_us",
                  "must be <= 1e+09"},
        BoundCase{"rate_slow", kCamera + kSim + "rate_hz = 1e-9\n", "trigger.rate_hz",
                  "must be in [0.001, 1e+06] (a trigger period of 1 us to 1000 s)"},
        BoundCase{"rate_fast", kCamera + kSim + "rate_hz = 1e12\n", "trigger.rate_hz", "must be in [0.001, 1e+06]"},
        BoundCase{"exposure_a", kCamera + kSim + "[trigger.camera]\nexposure_a_us = 1e10\n",
                  "trigger.camera.exposure_a_us", kCeiling},
        BoundCase{"interframe", kCamera + kSim + "[trigger.camera]\ninterframe_us = 1e300\n",
                  "trigger.camera.interframe_us", kCeiling},
        BoundCase{"exposure_b", kCamera + kSim + "[trigger.camera]\nexposure_b_us = 9.3e15\n",
                  "trigger.camera.exposure_b_us", kCeiling},
        BoundCase{"source_pulse_width",
                  kCamera + kSim + "dt_us = 1e8\nrate_hz = 0.001\n[[trigger.light_sources]]\nname = \"s\"\n"
                                   "pulse_width_us = 9.3e15\n",
                  "trigger.light_sources[0].pulse_width_us", kCeiling},
        BoundCase{"flashlamp_lead",
                  kCamera + kSim + "[[trigger.light_sources]]\nname = \"s\"\nkind = \"laser\"\nflashlamp_lead_us = 9.3e15\n",
                  "trigger.light_sources[0].flashlamp_lead_us", kCeiling},
        BoundCase{"channel_delay", kCamera + kChannel + "delay_us = 9.3e15\n", "trigger.channels[0].delay_us", kCeiling},
        BoundCase{"channel_width", kCamera + kChannel + "width_us = 9.3e15\n", "trigger.channels[0].width_us", kCeiling},
        BoundCase{"roi_width",
                  "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 70000\nheight = 48\n",
                  "cameras[0].roi.width", "70000 must be <= 65536"},
        BoundCase{"roi_offset",
                  "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\noffset_y = 2147483647\nwidth = 64\n"
                  "height = 48\n",
                  "cameras[0].roi.offset_y", "must be <= 65536"}),
    [](const ::testing::TestParamInfo<BoundCase>& info) { return std::string(info.param.name); });

TEST(TimeBounds, TimesJustInsideTheBoundsAreAccepted) {
  const std::string doc = kCamera + kSim + "rate_hz = 0.001\ndt_us = 1e8\npulse_width_us = 10\n" +
                          "[trigger.camera]\nexposure_a_us = 1e9\ninterframe_us = 1e9\nexposure_b_us = 1e9\n";
  const auto issues = check_rig_config(doc, "rig.toml");
  EXPECT_TRUE(issues.empty()) << dump(issues);
}

std::string rig_with_id(const std::string& toml_string) {
  return "[[cameras]]\nid = " + toml_string + "\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 8\nheight = 8\n";
}

TEST(CameraIds, EveryForbiddenIdIsRefusedWithItsReason) {
  struct Case {
    std::string toml;
    std::string reason;
  };
  for (const Case& c : {Case{R"("a/b")", "contains '/'"}, Case{R"("..")", "is '.' or '..'"},
                        Case{R"(".")", "is '.' or '..'"}, Case{R"("a\u0000b")", "contains a NUL byte"},
                        Case{R"("cam\u001b[31m")", "control character U+001B"},
                        Case{"\"" + std::string(129, 'c') + "\"", "129 bytes long"}}) {
    const auto issues = check_rig_config(rig_with_id(c.toml), "rig.toml");
    ASSERT_EQ(issues.size(), 1u) << c.toml << "\n" << dump(issues);
    EXPECT_EQ(issues[0].key, "cameras[0].id");
    EXPECT_EQ(issues[0].line, 2);
    EXPECT_NE(issues[0].message.find(c.reason), std::string::npos) << issues[0].to_string();
    EXPECT_NE(issues[0].message.find("is not allowed"), std::string::npos) << issues[0].to_string();
    EXPECT_EQ(issues[0].message.find('\x1b'), std::string::npos) << "raw escape byte in the message";
    EXPECT_EQ(issues[0].message.find('\0'), std::string::npos) << "raw NUL in the message";
  }
  // A NUL used to cut the id silently: "a\0b" and "a" became the same camera.
  EXPECT_TRUE(check_rig_config(rig_with_id(R"("kamera \u00e4")"), "rig.toml").empty()) << "UTF-8 ids are fine";
}

class CameraIdsCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!testing::tomorig_built()) GTEST_SKIP() << "tomorig is not built (" << TOMORIG_BINARY << ")";
  }
  testing::TempDir dir_;
};

TEST_F(CameraIdsCli, ConfigCheckRefusesPathIdsAndHugeTimes) {
  for (const std::string id : {"a/b", ".."}) {
    const auto file = dir_.write("rig.toml", rig_with_id("\"" + id + "\""));
    const testing::CliResult r = testing::run_tomorig("config check " + testing::shell_quoted(file.string()));
    EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
    EXPECT_NE(r.err.find(file.string() + ":2: cameras[0].id: \"" + id + "\" is not allowed"), std::string::npos)
        << r.err;
  }
  const auto file = dir_.write("width.toml", kCamera + kChannel + "width_us = 9.3e15\n");
  const testing::CliResult r = testing::run_tomorig("config check " + testing::shell_quoted(file.string()));
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("trigger.channels[0].width_us: 9300000000000000 must be <= 1e+09"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace tomorig::config
