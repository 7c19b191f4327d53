// Bad input to the correlator: each rejected with tomorig::Error (bad_input) naming the field.
#include <string>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/correlation/correlate.h"
#include "volume_pair.h"

namespace {

using namespace tomorig::piv;

// Runs `f`, expecting a bad_input error whose message contains `needle`.
template <typename F>
void expect_bad_input(F&& f, const std::string& needle) {
  try {
    f();
    FAIL() << "expected bad_input mentioning '" << needle << "'";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

CorrelationOptions one_pass(WindowSize w, double overlap = 0.5) {
  CorrelationOptions o;
  CorrelationPass p;
  p.window = w;
  p.overlap = overlap;
  o.passes.push_back(p);
  return o;
}

TEST(CorrelationOptions, DefaultMultigridIsValid) {
  EXPECT_NO_THROW(CorrelationOptions::multigrid({16, 16, 16}, 0.75, 2).validate(corr_test::test_grid(64, 64, 32)));
}

TEST(CorrelationOptions, RejectsWindowLargerThanVolume) {
  expect_bad_input([] { one_pass({32, 32, 64}).validate(corr_test::test_grid(64, 64, 32)); }, "window.z");
  expect_bad_input([] { one_pass({128, 32, 16}).validate(corr_test::test_grid(64, 64, 32)); }, "larger than the volume");
}

TEST(CorrelationOptions, RejectsOverlapOutOfRange) {
  expect_bad_input([] { one_pass({16, 16, 16}, 0.95).validate(corr_test::test_grid(64, 64, 32)); }, "overlap");
  expect_bad_input([] { one_pass({16, 16, 16}, -0.1).validate(corr_test::test_grid(64, 64, 32)); }, "overlap");
}

TEST(CorrelationOptions, RejectsOtherFields) {
  const auto grid = corr_test::test_grid(64, 64, 32);
  expect_bad_input([&] { CorrelationOptions{}.validate(grid); }, "passes");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.passes[0].downsample = 3; o.validate(grid); }, "downsample");
  expect_bad_input([&] { auto o = one_pass({18, 16, 16}); o.passes[0].downsample = 4; o.validate(grid); }, "window.x");
  expect_bad_input([&] { auto o = one_pass({2, 16, 16}); o.validate(grid); }, "window.x");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.min_peak = 1.5; o.validate(grid); }, "min_peak");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.max_displacement = -1; o.validate(grid); }, "max_displacement");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.median_test.epsilon = 0; o.validate(grid); }, "median_test.epsilon");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.median_test.threshold = -2; o.validate(grid); }, "median_test.threshold");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.min_illumination = 2; o.validate(grid); }, "min_illumination");
  expect_bad_input([&] { auto o = one_pass({16, 16, 16}); o.threads = -1; o.validate(grid); }, "threads");
}

TEST(Correlate, RejectsVolumesOnDifferentGrids) {
  const tomorig::DenseVolume a(corr_test::test_grid(64, 64, 32)), b(corr_test::test_grid(64, 64, 16));
  CorrelationReport report;
  expect_bad_input([&] { correlate(a, b, one_pass({16, 16, 16}), report); }, "different grids");
  tomorig::SparseVolume sa, sb;
  sa.grid = corr_test::test_grid(64, 64, 32);
  sb.grid = sa.grid;
  sb.grid.voxel_size *= 2;
  expect_bad_input([&] { correlate(sa, sb, one_pass({16, 16, 16}), report); }, "different grids");
}

TEST(Correlate, RejectsTooLargeWindowAtCallTime) {
  const tomorig::DenseVolume a(corr_test::test_grid(32, 32, 16));
  CorrelationReport report;
  expect_bad_input([&] { correlate(a, a, one_pass({32, 32, 32}), report); }, "larger than the volume");
}

}  // namespace
