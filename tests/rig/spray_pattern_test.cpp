// The rig file's spray patterns (config's words) onto the simulator's: each word lands on the
// pattern whose truth flow name is that same word, and an unknown word names the option and
// the allowed words.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/config/vocabulary.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/simulate_spray.h"

namespace tomorig::testing {
namespace {

TEST(SprayPattern, EachRigFileWordIsTheSimulatorsPatternOfThatName) {
  for (const auto& w : config::Vocabulary<config::SprayPattern>::words) {
    EXPECT_EQ(sim::to_string(rig::sim_spray_pattern(w.value)), w.name);
    EXPECT_EQ(rig::parse_spray_pattern(std::string(w.name), "--spray"), rig::sim_spray_pattern(w.value));
  }
}

TEST(SprayPattern, AnUnknownWordNamesTheOptionAndTheAllowedWords) {
  try {
    rig::parse_spray_pattern("swirl", "--spray");
    FAIL() << "swirl was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_EQ(std::string(e.what()), "--spray swirl: unknown spray pattern, use one of jet-in-crossflow, hollow-cone");
  }
}

}  // namespace
}  // namespace tomorig::testing
