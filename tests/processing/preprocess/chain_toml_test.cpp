// The TOML form of a chain: a full chain parses into the right steps, and every mistake is
// refused with the key path, its line and what is allowed.
#include <string>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/chain_spec.h"

namespace tomorig::preprocess {
namespace {

// The error message of parsing `text`, or "" if it parsed.
std::string error_of(const std::string& text) {
  try {
    parse_chain(text, "chain.toml");
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    return e.what();
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(PreprocessChainToml, ParsesEveryStep) {
  const ChainSpec spec = parse_chain(R"(
[[preprocess.steps]]
kind = "invert"
max = 4095
[[preprocess.steps]]
kind = "subtract_dark"
file = "dark.h5"
[[preprocess.steps]]
kind = "subtract_minimum"
[[preprocess.steps]]
kind = "subtract_local_minimum"
size = 11
[[preprocess.steps]]
kind = "median"
[[preprocess.steps]]
kind = "highpass"
sigma = 3.5
[[preprocess.steps]]
kind = "lowpass"
sigma = 1
[[preprocess.steps]]
kind = "normalize"
by = "average_image"
target = 500
[[preprocess.steps]]
kind = "flat_field"
file = "bright.h5"
[[preprocess.steps]]
kind = "clip"
sigmas = 3
subtract = true
)",
                                     "chain.toml");
  ASSERT_EQ(spec.steps.size(), 10u);
  EXPECT_EQ(spec.steps[0].kind, StepKind::invert);
  EXPECT_EQ(spec.steps[0].max, 4095.0);
  EXPECT_EQ(spec.steps[1].file, "dark.h5");
  EXPECT_TRUE(needs_reference_image(spec.steps[1]));
  EXPECT_TRUE(needs_sequence_image(spec.steps[2]));
  EXPECT_EQ(spec.steps[3].size, 11);
  EXPECT_EQ(spec.steps[4].size, 3);
  EXPECT_EQ(spec.steps[5].sigma, 3.5);
  EXPECT_EQ(spec.steps[6].sigma, 1.0);
  EXPECT_EQ(spec.steps[7].by, NormalizeBy::average_image);
  EXPECT_TRUE(needs_sequence_image(spec.steps[7]));
  EXPECT_EQ(spec.steps[7].target, 500.0);
  EXPECT_TRUE(needs_reference_image(spec.steps[8]));
  EXPECT_TRUE(spec.steps[9].use_sigmas);
  EXPECT_EQ(spec.steps[9].sigmas, 3.0);
  EXPECT_TRUE(spec.steps[9].subtract);
}

TEST(PreprocessChainToml, UnknownKeyIsNamedWithItsLineAndTheAllowedKeys) {
  const std::string e = error_of("[[preprocess.steps]]\nkind = \"median\"\n\n[[preprocess.steps]]\nkind = \"highpass\"\nsize = 3\n");
  EXPECT_TRUE(contains(e, "preprocess.steps[1].size")) << e;
  EXPECT_TRUE(contains(e, "line 6")) << e;
  EXPECT_TRUE(contains(e, "allowed: sigma")) << e;
}

TEST(PreprocessChainToml, BadValueNamesTheKeyLineAndRange) {
  const std::string e = error_of("[[preprocess.steps]]\nkind = \"subtract_local_minimum\"\nsize = 1\n");
  EXPECT_TRUE(contains(e, "preprocess.steps[0]")) << e;
  EXPECT_TRUE(contains(e, "line 1")) << e;
  EXPECT_TRUE(contains(e, "size must be an integer from 2 to 101, got 1")) << e;

  const std::string t = error_of("[[preprocess.steps]]\nkind = \"lowpass\"\nsigma = \"wide\"\n");
  EXPECT_TRUE(contains(t, "preprocess.steps[0].sigma (line 3): must be a number")) << t;
}

TEST(PreprocessChainToml, UnknownKindListsTheKinds) {
  const std::string e = error_of("[[preprocess.steps]]\nkind = \"sharpen\"\n");
  EXPECT_TRUE(contains(e, "preprocess.steps[0].kind (line 2)")) << e;
  EXPECT_TRUE(contains(e, "subtract_local_minimum")) << e;
  const std::string missing = error_of("[[preprocess.steps]]\nsize = 3\n");
  EXPECT_TRUE(contains(missing, "kind")) << missing;
}

TEST(PreprocessChainToml, ExactlyOneOfAlternativeKeys) {
  EXPECT_TRUE(contains(error_of("[[preprocess.steps]]\nkind = \"clip\"\n"), "exactly one of 'level'"));
  EXPECT_TRUE(contains(error_of("[[preprocess.steps]]\nkind = \"subtract_dark\"\nlevel = 1\nfile = \"d.h5\"\n"),
                       "exactly one of 'file'"));
  EXPECT_TRUE(contains(error_of("[[preprocess.steps]]\nkind = \"normalize\"\nby = \"median\"\n"), "\"average_image\""));
}

TEST(PreprocessChainToml, StructureErrors) {
  EXPECT_TRUE(contains(error_of("[preprocess]\n"), "preprocess.steps must be a non-empty array"));
  EXPECT_TRUE(contains(error_of("[other]\nx = 1\n"), "other (line 1)"));
  EXPECT_TRUE(contains(error_of("[preprocess]\nstep = 1\n"), "preprocess.step (line 2)"));
  const std::string syntax = error_of("[[preprocess.steps]]\nkind = \"median\n");
  EXPECT_TRUE(contains(syntax, "chain.toml: line 2")) << syntax;
}

TEST(PreprocessChainToml, MissingFileIsABadInput) {
  try {
    read_chain_file("/nonexistent/chain.toml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_TRUE(contains(e.what(), "/nonexistent/chain.toml"));
  }
}

}  // namespace
}  // namespace tomorig::preprocess
