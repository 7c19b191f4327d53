// The rig file's closed vocabularies (rig_vocabulary.h): every word parses to its value and
// prints back as the same word, every value the file can state has a word, and an unknown word
// in a rig file is named with its key, the allowed words and the closest one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <string>
#include <string_view>

#include "config_test_support.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/config/vocabulary.h"

namespace tomorig::config {
namespace {
using test_support::dump;

// Each word -> value -> the same word; `values` enum values in all (the last ones may have no word).
template <typename E>
void expect_round_trip(int values, int without_word = 0) {
  std::set<std::string_view> words;
  for (const auto& w : Vocabulary<E>::words) {
    EXPECT_TRUE(words.insert(w.name).second) << "the word \"" << w.name << "\" is listed twice";
    const std::optional<E> parsed = parse<E>(w.name);
    ASSERT_TRUE(parsed.has_value()) << w.name;
    EXPECT_EQ(*parsed, w.value) << w.name;
    EXPECT_EQ(to_string(*parsed), w.name);
  }
  // Every value the rig file can state has exactly one word.
  for (int v = 0; v < values - without_word; ++v) {
    const auto value = static_cast<E>(v);
    const std::string_view word = to_string(value);
    EXPECT_NE(word, "unknown") << "value " << v << " has no word";
    EXPECT_EQ(parse<E>(word), value) << word;
  }
  EXPECT_EQ(static_cast<int>(words.size()), values - without_word);
  EXPECT_FALSE(parse<E>("").has_value());
  EXPECT_FALSE(parse<E>("no-such-word").has_value());
  // TOML strings are exact: a word in capitals is not the word.
  std::string upper(Vocabulary<E>::words[0].name);
  std::transform(upper.begin(), upper.end(), upper.begin(), [](unsigned char c) { return std::toupper(c); });
  EXPECT_FALSE(parse<E>(upper).has_value()) << upper;
}

TEST(Vocabulary, EveryWordParsesAndPrintsBackTheSame) {
  expect_round_trip<CameraBackend>(3);
  expect_round_trip<TriggerBackend>(2);
  expect_round_trip<FrameMode>(3);
  expect_round_trip<LightSourceKind>(3, /*without_word=*/1);  // unknown: a kind not stated
  expect_round_trip<ChannelRole>(4);
  expect_round_trip<PulseSelect>(3);
  expect_round_trip<LightSheetProfile>(3);
  expect_round_trip<SprayPattern>(2);
}

TEST(Vocabulary, TheRigFilesSpellingIsUnchanged) {
  EXPECT_EQ(allowed_words<LightSourceKind>(), "laser, led");
  EXPECT_EQ(allowed_words<ChannelRole>(), "light, camera, flashlamp, pulse_generator");
  EXPECT_EQ(allowed_words<PulseSelect>(), "first, second, both");
  EXPECT_EQ(allowed_words<LightSheetProfile>(), "uniform, gaussian, tophat");
  EXPECT_EQ(allowed_words<SprayPattern>(), "jet-in-crossflow, hollow-cone");
  EXPECT_EQ(allowed_words<FrameMode>(), "hardware, two_triggers, free_run");
  EXPECT_EQ(allowed_words<CameraBackend>(), "aravis, simulated, gentl");
  EXPECT_EQ(allowed_words<TriggerBackend>(), "gpio, simulated");
  EXPECT_EQ(to_string(LightSourceKind::unknown), "unknown");
}

const std::string kCamera = "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 64\nheight = 48\n\n";

// A rig file with every vocabulary written in words, read back and printed: the same words.
TEST(Vocabulary, ARigFilesWordsDecodeToTheirValues) {
  const RigConfig rig = parse_rig_config(kCamera + R"([trigger]
backend = "simulated"
[[trigger.light_sources]]
name = "head"
kind = "laser"
flashlamp_lead_us = 180
[[trigger.channels]]
name = "lamp"
role = "flashlamp"
light_source = "head"
pulses = "second"
[[trigger.channels]]
name = "q"
role = "light"
light_source = "head"
pulses = "first"
[simulation]
light_sheet = "tophat"
spray = "hollow-cone"
)");
  ASSERT_EQ(rig.trigger.light_sources.size(), 1u);
  EXPECT_EQ(to_string(rig.trigger.light_sources[0].kind), "laser");
  ASSERT_EQ(rig.trigger.channels.size(), 2u);
  EXPECT_EQ(to_string(rig.trigger.channels[0].role), "flashlamp");
  EXPECT_EQ(to_string(rig.trigger.channels[0].pulses), "second");
  EXPECT_EQ(to_string(rig.trigger.channels[1].role), "light");
  EXPECT_EQ(to_string(rig.trigger.channels[1].pulses), "first");
  ASSERT_TRUE(rig.simulation.has_value());
  EXPECT_EQ(rig.simulation->light_sheet, LightSheetProfile::tophat);
  EXPECT_EQ(rig.simulation->spray, SprayPattern::hollow_cone);
  EXPECT_EQ(to_string(rig.cameras[0].backend), "simulated");
}

// A misspelt word: the key, the word, the allowed words and the closest one.
TEST(Vocabulary, AMisspeltWordIsNamedWithTheAllowedWordsAndASuggestion) {
  struct Case {
    std::string doc, key, message;
  };
  const Case cases[] = {
      {kCamera + "[trigger]\nbackend = \"simulated\"\n[[trigger.channels]]\nname = \"l\"\nrole = \"light\"\npulses = \"boht\"\n",
       "trigger.channels[0].pulses", "\"boht\" must be one of first, second, both, did you mean \"both\"?"},
      {kCamera + "[trigger]\nbackend = \"simulated\"\n[[trigger.channels]]\nname = \"l\"\nrole = \"ligth\"\n",
       "trigger.channels[0].role", "\"ligth\" must be one of light, camera, flashlamp, pulse_generator, did you mean \"light\"?"},
      {kCamera + "[trigger]\nbackend = \"simulated\"\n[[trigger.light_sources]]\nname = \"s\"\nkind = \"lazer\"\n",
       "trigger.light_sources[0].kind", "\"lazer\" must be one of laser, led, did you mean \"laser\"?"},
      {kCamera + "[simulation]\nlight_sheet = \"gausian\"\n", "simulation.light_sheet",
       "\"gausian\" must be one of uniform, gaussian, tophat, did you mean \"gaussian\"?"},
      {kCamera + "[simulation]\nspray = \"hollow_cone\"\n", "simulation.spray",
       "\"hollow_cone\" must be one of jet-in-crossflow, hollow-cone, did you mean \"hollow-cone\"?"},
  };
  for (const Case& c : cases) {
    const auto issues = check_rig_config(c.doc, "rig.toml");
    const bool found = std::any_of(issues.begin(), issues.end(), [&](const ConfigIssue& i) {
      return i.key == c.key && i.message == c.message;
    });
    EXPECT_TRUE(found) << "expected " << c.key << ": " << c.message << "\ngot:\n" << dump(issues);
  }
}

}  // namespace
}  // namespace tomorig::config
