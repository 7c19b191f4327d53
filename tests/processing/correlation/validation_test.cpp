// Validation on fields of known content: injected outliers, low peaks, large vectors, masks.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tomorig/processing/correlation/vector_validation.h"

namespace {

using namespace tomorig;
using namespace tomorig::piv;

// A smooth field (a linear shear plus 0.05 voxel noise), every vector valid with peak 0.6.
VectorField smooth_field(int nx, int ny, int nz) {
  VectorField f(nx, ny, nz);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const std::size_t n = f.linear(i, j, k);
        f.displacement[n] = {1.0f + 0.2f * j + noise(rng), -2.0f + noise(rng), 0.5f + 0.1f * i + noise(rng)};
        f.status[n] = VectorStatus::valid;
        f.peak[n] = 0.6f;
      }
  return f;
}

TEST(ValidateField, MedianTestFlagsAndReplacesInjectedOutliers) {
  VectorField f = smooth_field(8, 8, 6);
  const VectorField truth = f;
  const std::size_t outliers[] = {f.linear(3, 3, 3), f.linear(0, 0, 0), f.linear(7, 5, 2), f.linear(4, 6, 1)};
  for (std::size_t n : outliers) f.displacement[n] = {9.0f, -7.0f, 4.0f};
  const ValidationCounts counts = validate_field(f, CorrelationOptions{});
  EXPECT_EQ(counts.median_outliers, 4u);
  EXPECT_EQ(counts.replaced, 4u);
  for (std::size_t n : outliers) {
    EXPECT_EQ(f.status[n], VectorStatus::replaced);
    // The neighbourhood median of a linear field with 0.05 noise: within a few tenths of the truth.
    EXPECT_NEAR(f.displacement[n].x, truth.displacement[n].x, 0.3);
    EXPECT_NEAR(f.displacement[n].y, truth.displacement[n].y, 0.3);
    EXPECT_NEAR(f.displacement[n].z, truth.displacement[n].z, 0.3);
  }
  std::size_t valid = 0;
  for (VectorStatus s : f.status) valid += s == VectorStatus::valid;
  EXPECT_EQ(valid, f.count() - 4);  // no good vector flagged at this noise level
}

TEST(ValidateField, LowPeakIsInvalidAndNotReplaced) {
  VectorField f = smooth_field(5, 5, 5);
  f.peak[f.linear(2, 2, 2)] = 0.05f;
  const ValidationCounts counts = validate_field(f, CorrelationOptions{});
  EXPECT_EQ(counts.low_peak, 1u);
  EXPECT_EQ(f.status[f.linear(2, 2, 2)], VectorStatus::invalid);
}

TEST(ValidateField, MaximumDisplacementReplacesLargeVectors) {
  VectorField f = smooth_field(5, 5, 5);
  CorrelationOptions options;
  options.median_test.enabled = false;
  options.max_displacement = 5.0;
  f.displacement[f.linear(1, 2, 3)] = {0.0f, 6.0f, 0.0f};
  const ValidationCounts counts = validate_field(f, options);
  EXPECT_EQ(counts.too_large, 1u);
  EXPECT_EQ(f.status[f.linear(1, 2, 3)], VectorStatus::replaced);
  EXPECT_NEAR(f.displacement[f.linear(1, 2, 3)].y, -2.0f, 0.2);
}

TEST(ValidateField, MaskedNodesAreInvalid) {
  VectorField f = smooth_field(4, 4, 4);
  std::vector<std::uint8_t> mask(f.count(), 1);
  mask[f.linear(1, 1, 1)] = 0;
  mask[f.linear(2, 3, 0)] = 0;
  const ValidationCounts counts = validate_field(f, CorrelationOptions{}, mask);
  EXPECT_EQ(counts.masked, 2u);
  EXPECT_EQ(f.status[f.linear(1, 1, 1)], VectorStatus::invalid);
  EXPECT_EQ(f.status[f.linear(2, 3, 0)], VectorStatus::invalid);
  EXPECT_EQ(f.status[f.linear(0, 0, 0)], VectorStatus::valid);
}

}  // namespace
