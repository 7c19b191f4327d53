// The trigger keys of the rig config: camera timing, light sources with kinds and safety
// limits, channel roles, light-source references, pulses, delays, widths, GPIO wiring and
// resolution. Every problem is named by key path and line and says what is allowed.
#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "config_test_support.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config {
namespace {
using test_support::dump;
using test_support::line_containing;

// One simulated camera, then `trigger` (the [trigger] table and its sub-tables).
std::string rig_with_trigger(const std::string& trigger) {
  return "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 64\nheight = 48\n\n" + trigger;
}

const std::string kSim = "[trigger]\nbackend = \"simulated\"\n";



// Expects an issue for `key` on the line holding `at` whose message contains `text`.
void expect_issue(const std::string& doc, const std::string& key, const std::string& at, const std::string& text) {
  const auto issues = check_rig_config(doc, "rig.toml");
  auto it = std::find_if(issues.begin(), issues.end(), [&](const ConfigIssue& i) {
    return i.key == key && i.message.find(text) != std::string::npos;
  });
  ASSERT_NE(it, issues.end()) << "no issue for " << key << " containing \"" << text << "\"; got:\n"
                              << dump(issues) << "in:\n" << doc;
  EXPECT_EQ(it->line, line_containing(doc, at)) << it->to_string();
}

// ---- valid input ---------------------------------------------------------------------------

TEST(TriggerConfig, ReadsEveryTriggerKey) {
  const std::string doc = rig_with_trigger(R"([trigger]
backend = "gpio"
dt_us = 40.0
pulse_width_us = 0.008
gpio_resolution_us = 500
[trigger.camera]
exposure_a_us = 15
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
name = "generator"
role = "pulse_generator"
delay_us = 0.085
chip = "gpiochip0"
line = 5
[[trigger.channels]]
name = "lamp1"
role = "flashlamp"
light_source = "head1"
pulses = "first"
width_us = 10
[[trigger.channels]]
name = "qswitch1"
role = "light"
light_source = "head1"
pulses = "first"
delay_us = 0.1
[[trigger.channels]]
name = "led"
role = "light"
light_source = "led1"
[[trigger.channels]]
name = "cams"
role = "camera"
)");
  const RigConfig rig = parse_rig_config(doc);
  const TriggerConfig& t = rig.trigger;
  EXPECT_DOUBLE_EQ(t.gpio_resolution_us, 500.0);
  EXPECT_DOUBLE_EQ(t.camera.exposure_a_us, 15.0);
  EXPECT_DOUBLE_EQ(t.camera.interframe_us, 0.2);
  EXPECT_DOUBLE_EQ(t.camera.exposure_b_us, 2000.0);

  ASSERT_EQ(t.light_sources.size(), 2u);
  const LightSourceConfig& head = t.light_sources[0];
  EXPECT_EQ(head.name, "head1");
  EXPECT_EQ(head.kind, LightSourceKind::laser);
  EXPECT_DOUBLE_EQ(head.pulse_width_us, 0.008);  // from trigger.pulse_width_us
  EXPECT_DOUBLE_EQ(head.flashlamp_lead_us, 180.0);
  EXPECT_FALSE(head.max_pulse_width_us.has_value());
  EXPECT_FALSE(head.max_duty_cycle.has_value());
  ASSERT_TRUE(head.max_rate_hz.has_value());
  EXPECT_DOUBLE_EQ(*head.max_rate_hz, 15.0);
  const LightSourceConfig& led = t.light_sources[1];
  EXPECT_EQ(led.kind, LightSourceKind::led);
  EXPECT_DOUBLE_EQ(led.pulse_width_us, 0.4);
  EXPECT_DOUBLE_EQ(led.max_pulse_width_us.value_or(0), 1.5);
  EXPECT_DOUBLE_EQ(led.max_duty_cycle.value_or(0), 0.0005);
  EXPECT_FALSE(led.max_rate_hz.has_value());

  ASSERT_EQ(t.channels.size(), 5u);
  EXPECT_EQ(t.channels[0].role, ChannelRole::pulse_generator);
  EXPECT_DOUBLE_EQ(t.channels[0].delay_us, 0.085);
  EXPECT_EQ(t.channels[0].chip, "gpiochip0");
  EXPECT_EQ(t.channels[0].line, 5);
  EXPECT_EQ(t.channels[1].role, ChannelRole::flashlamp);
  EXPECT_EQ(t.channels[1].light_source, "head1");
  EXPECT_EQ(t.channels[1].pulses, PulseSelect::first);
  EXPECT_DOUBLE_EQ(t.channels[1].width_us.value_or(0), 10.0);
  EXPECT_DOUBLE_EQ(t.channels[2].delay_us, 0.1);
  EXPECT_EQ(t.channels[3].pulses, PulseSelect::both);  // the default
  EXPECT_FALSE(t.channels[3].width_us.has_value());
  // With a pulse generator, channels without chip/line are the generator's outputs.
  EXPECT_TRUE(t.channels[4].chip.empty());
  EXPECT_EQ(t.channels[4].line, -1);
}

TEST(TriggerConfig, KeysLeftOutTakeTheirDefaults) {
  const RigConfig rig = parse_rig_config(rig_with_trigger(kSim + "[[trigger.light_sources]]\nname = \"l\"\n"));
  const TriggerConfig& t = rig.trigger;
  EXPECT_DOUBLE_EQ(t.gpio_resolution_us, 1000.0);
  EXPECT_DOUBLE_EQ(t.camera.exposure_a_us, 20.0);
  EXPECT_DOUBLE_EQ(t.camera.interframe_us, 0.12);
  EXPECT_DOUBLE_EQ(t.camera.exposure_b_us, 1000.0);
  ASSERT_EQ(t.light_sources.size(), 1u);
  EXPECT_EQ(t.light_sources[0].kind, LightSourceKind::unknown);  // not stated: the trigger's strictest limits
  EXPECT_DOUBLE_EQ(t.light_sources[0].pulse_width_us, 0.01);
  EXPECT_DOUBLE_EQ(t.light_sources[0].flashlamp_lead_us, 0.0);
}

TEST(TriggerConfig, LightChannelsWithoutDeclaredSourcesStillParse) {
  // Rigs written before [[trigger.light_sources]] existed: each light channel is its own source.
  const RigConfig rig =
      parse_rig_config(rig_with_trigger(kSim + "[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\n"));
  ASSERT_EQ(rig.trigger.channels.size(), 1u);
  EXPECT_TRUE(rig.trigger.channels[0].light_source.empty());
}

TEST(TriggerConfig, DefaultRigDeclaresItsLightSource) {
  const RigConfig rig = default_rig_config();
  ASSERT_EQ(rig.trigger.light_sources.size(), 1u);
  EXPECT_EQ(rig.trigger.light_sources[0].name, "laser");
  ASSERT_FALSE(rig.trigger.channels.empty());
  EXPECT_EQ(rig.trigger.channels[0].light_source, "laser");
  EXPECT_DOUBLE_EQ(rig.trigger.camera.exposure_b_us, 1000.0);
}

// ---- problems: key path, line, what is allowed -----------------------------------------------

struct TriggerCase {
  const char* label;
  std::string trigger;  // the [trigger] part of the document
  const char* key;
  const char* at;       // a fragment of the line the issue must point at
  const char* message;  // the message must contain this
};

class TriggerIssues : public ::testing::TestWithParam<TriggerCase> {};

TEST_P(TriggerIssues, NameKeyLineAndWhatIsAllowed) {
  const TriggerCase& c = GetParam();
  expect_issue(rig_with_trigger(c.trigger), c.key, c.at, c.message);
}

const std::string kCamera = kSim + "[trigger.camera]\n";
const std::string kSource = kSim + "[[trigger.light_sources]]\nname = \"s\"\n";
// Two declared sources, then a channel whose body the case adds.
const std::string kTwoSources = kSim +
                                "[[trigger.light_sources]]\nname = \"laser\"\nkind = \"laser\"\n"
                                "[[trigger.light_sources]]\nname = \"led1\"\nkind = \"led\"\n"
                                "[[trigger.channels]] # channel\nname = \"c\"\n";

INSTANTIATE_TEST_SUITE_P(
    Config, TriggerIssues,
    ::testing::Values(
        // [trigger]
        TriggerCase{"gpio_resolution_fine", kSim + "gpio_resolution_us = 10\n", "trigger.gpio_resolution_us",
                    "gpio_resolution_us", "10 must be >= 100"},
        TriggerCase{"gpio_resolution_type", kSim + "gpio_resolution_us = \"1ms\"\n", "trigger.gpio_resolution_us",
                    "gpio_resolution_us", "expected a number, got string \"1ms\""},
        // [trigger.camera]
        TriggerCase{"exposure_a_zero", kCamera + "exposure_a_us = 0\n", "trigger.camera.exposure_a_us", "exposure_a_us",
                    "0 must be >= 0.001"},
        TriggerCase{"exposure_b_sub_ns", kCamera + "exposure_b_us = 0.0004\n", "trigger.camera.exposure_b_us",
                    "exposure_b_us", "0.0004 must be >= 0.001 (1 ns"},
        TriggerCase{"interframe_negative", kCamera + "interframe_us = -1\n", "trigger.camera.interframe_us",
                    "interframe_us", "-1 must be >= 0"},
        TriggerCase{"camera_unknown", kCamera + "exposure_us = 20\n", "trigger.camera.exposure_us", "exposure_us",
                    "unknown key, did you mean \"exposure_a_us\"?"},
        TriggerCase{"camera_not_table", kSim + "camera = 3\n", "trigger.camera", "camera = 3",
                    "expected a table [trigger.camera]"},
        // [[trigger.light_sources]]
        TriggerCase{"source_name_missing", kSim + "[[trigger.light_sources]]\nkind = \"led\"\n",
                    "trigger.light_sources[0].name", "[[trigger.light_sources]]", "required key is missing"},
        TriggerCase{"source_kind", kSource + "kind = \"lamp\"\n", "trigger.light_sources[0].kind", "lamp",
                    "\"lamp\" must be one of laser, led"},
        TriggerCase{"source_width_zero", kSource + "pulse_width_us = 0\n", "trigger.light_sources[0].pulse_width_us",
                    "pulse_width_us", "0 must be >= 0.001"},
        TriggerCase{"source_width_dt", kSource + "pulse_width_us = 150\n", "trigger.light_sources[0].pulse_width_us",
                    "pulse_width_us", "150 must be < trigger.dt_us (100)"},
        TriggerCase{"lead_negative", kSource + "kind = \"laser\"\nflashlamp_lead_us = -5\n",
                    "trigger.light_sources[0].flashlamp_lead_us", "flashlamp_lead_us", "-5 must be >= 0"},
        TriggerCase{"lead_on_led", kSource + "kind = \"led\"\nflashlamp_lead_us = 180\n",
                    "trigger.light_sources[0].flashlamp_lead_us", "flashlamp_lead_us",
                    "only lasers have a flash lamp, but this source is kind = \"led\""},
        TriggerCase{"lead_without_kind", kSource + "flashlamp_lead_us = 180\n",
                    "trigger.light_sources[0].flashlamp_lead_us", "flashlamp_lead_us", "of no stated kind"},
        TriggerCase{"duty_above_one", kSource + "max_duty_cycle = 1.5\n", "trigger.light_sources[0].max_duty_cycle",
                    "max_duty_cycle", "1.5 must be in (0, 1]"},
        TriggerCase{"duty_zero", kSource + "max_duty_cycle = 0\n", "trigger.light_sources[0].max_duty_cycle",
                    "max_duty_cycle", "0 must be in (0, 1]"},
        TriggerCase{"max_width_ceiling", kSource + "max_pulse_width_us = 5000\n",
                    "trigger.light_sources[0].max_pulse_width_us", "max_pulse_width_us",
                    "5000 must be in [0.001, 1000]"},
        TriggerCase{"max_width_negative", kSource + "max_pulse_width_us = -1\n",
                    "trigger.light_sources[0].max_pulse_width_us", "max_pulse_width_us", "-1 must be in [0.001, 1000]"},
        TriggerCase{"max_rate_zero", kSource + "max_rate_hz = 0\n", "trigger.light_sources[0].max_rate_hz",
                    "max_rate_hz", "0 must be in (0, 100000]"},
        TriggerCase{"max_rate_ceiling", kSource + "max_rate_hz = 1e6\n", "trigger.light_sources[0].max_rate_hz",
                    "max_rate_hz", "1000000 must be in (0, 100000]"},
        TriggerCase{"source_unknown_key", kSource + "max_duty = 0.01\n", "trigger.light_sources[0].max_duty",
                    "max_duty", "unknown key, did you mean \"max_duty_cycle\"?"},
        TriggerCase{"source_duplicate", kSource + "[[trigger.light_sources]]\nname = \"s\" # again\n",
                    "trigger.light_sources[1].name", "# again",
                    "\"s\" is already used by trigger.light_sources[0] (line"},
        TriggerCase{"sources_not_tables", kSim + "light_sources = 3\n", "trigger.light_sources", "light_sources",
                    "expected an array of tables ([[trigger.light_sources]])"},
        // [[trigger.channels]]
        TriggerCase{"role_new_list", kSim + "[[trigger.channels]]\nname = \"x\"\nrole = \"strobe\"\n",
                    "trigger.channels[0].role", "strobe",
                    "\"strobe\" must be one of light, camera, flashlamp, pulse_generator"},
        TriggerCase{"source_not_declared", kTwoSources + "role = \"light\"\nlight_source = \"ghost\"\n",
                    "trigger.channels[0].light_source", "ghost",
                    "\"ghost\" is not a declared light source (declared: \"laser\", \"led1\")"},
        TriggerCase{"source_none_declared",
                    kSim + "[[trigger.channels]]\nname = \"c\"\nrole = \"light\"\nlight_source = \"ghost\"\n",
                    "trigger.channels[0].light_source", "ghost", "\"ghost\" is not a declared light source (none are declared)"},
        TriggerCase{"source_required_when_declared", kTwoSources + "role = \"light\"\n",
                    "trigger.channels[0].light_source", "# channel",
                    "required key is missing (expected a string naming a [[trigger.light_sources]] entry, declared: "
                    "\"laser\", \"led1\")"},
        TriggerCase{"flashlamp_needs_source", kSim + "[[trigger.channels]] # channel\nname = \"f\"\nrole = \"flashlamp\"\n",
                    "trigger.channels[0].light_source", "# channel", "a flashlamp channel fires the flash lamp of one laser"},
        TriggerCase{"flashlamp_on_led", kTwoSources + "role = \"flashlamp\"\nlight_source = \"led1\"\n",
                    "trigger.channels[0].light_source", "light_source = \"led1\"", "use a light source with kind = \"laser\""},
        TriggerCase{"source_on_camera", kTwoSources + "role = \"camera\"\nlight_source = \"laser\"\n",
                    "trigger.channels[0].light_source", "light_source = \"laser\"",
                    "only light and flashlamp channels fire a light source, and this channel's role is \"camera\""},
        TriggerCase{"pulses_value", kTwoSources + "role = \"light\"\nlight_source = \"laser\"\npulses = \"third\"\n",
                    "trigger.channels[0].pulses", "third", "\"third\" must be one of first, second, both"},
        TriggerCase{"pulses_on_generator", kTwoSources + "role = \"pulse_generator\"\npulses = \"first\"\n",
                    "trigger.channels[0].pulses", "pulses", "only light and flashlamp channels choose their pulses"},
        TriggerCase{"delay_negative", kTwoSources + "role = \"camera\"\ndelay_us = -1\n", "trigger.channels[0].delay_us",
                    "delay_us", "-1 must be >= 0"},
        TriggerCase{"width_zero", kTwoSources + "role = \"camera\"\nwidth_us = 0\n", "trigger.channels[0].width_us",
                    "width_us", "0 must be >= 0.001"},
        TriggerCase{"channel_unknown_key", kTwoSources + "role = \"camera\"\ndelay = 1\n", "trigger.channels[0].delay",
                    "delay = 1", "unknown key, did you mean \"delay_us\"?"},
        TriggerCase{"chip_without_line", kTwoSources + "role = \"camera\"\nchip = \"gpiochip0\"\n",
                    "trigger.channels[0].line", "# channel", "required when chip is given"},
        // gpio: every channel wired, unless a pulse generator makes the timing; the generator always.
        TriggerCase{"gpio_generator_unwired",
                    "[trigger]\nbackend = \"gpio\"\n[[trigger.channels]] # gen\nname = \"g\"\nrole = \"pulse_generator\"\n"
                    "[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n",
                    "trigger.channels[0].chip", "# gen",
                    "required key is missing (expected a string, e.g. \"gpiochip0\"): the gpio backend triggers the "
                    "pulse generator"},
        TriggerCase{"gpio_no_generator_unwired",
                    "[trigger]\nbackend = \"gpio\"\n[[trigger.channels]] # cam\nname = \"c\"\nrole = \"camera\"\n",
                    "trigger.channels[0].line", "# cam", "without a pulse_generator channel"}),
    [](const ::testing::TestParamInfo<TriggerCase>& info) { return std::string(info.param.label); });

TEST(TriggerConfig, GpioWithAPulseGeneratorNeedsWiringOnlyForIt) {
  const std::string doc = rig_with_trigger(
      "[trigger]\nbackend = \"gpio\"\n"
      "[[trigger.channels]]\nname = \"g\"\nrole = \"pulse_generator\"\nchip = \"gpiochip0\"\nline = 3\n"
      "[[trigger.channels]]\nname = \"c\"\nrole = \"camera\"\n"
      "[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\n");
  EXPECT_TRUE(check_rig_config(doc).empty()) << dump(check_rig_config(doc));
}

TEST(TriggerConfig, AllProblemsOfOneFileAreReportedTogether) {
  const std::string doc = rig_with_trigger(kSource + "kind = \"lamp\"\nmax_duty_cycle = 2\n" +
                                           "[[trigger.channels]]\nname = \"c\"\nrole = \"light\"\nlight_source = \"x\"\n");
  const auto issues = check_rig_config(doc);
  EXPECT_EQ(issues.size(), 3u) << dump(issues);
  // In file order, so a user fixes them top to bottom.
  EXPECT_TRUE(std::is_sorted(issues.begin(), issues.end(),
                             [](const ConfigIssue& a, const ConfigIssue& b) { return a.line < b.line; }));
}

}  // namespace
}  // namespace tomorig::config
