// Droplet blobs in a volume whose droplets are known: Gaussian blobs elongated along z, as a
// shadowgraphy reconstruction makes them, of two widths.
#include <cmath>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/particles/droplets.h"

namespace tomorig::particles {
namespace {

// Adds a blob of half-width `radius_voxel` in x and y (value >= half the peak within it) and
// three times longer in z.
void add_blob(DenseVolume& v, Vec3d centre_voxel, double radius_voxel, float peak) {
  const double s = radius_voxel / std::sqrt(2.0 * std::log(2.0));  // half maximum at the radius
  for (int k = 0; k < v.grid.nz; ++k)
    for (int j = 0; j < v.grid.ny; ++j)
      for (int i = 0; i < v.grid.nx; ++i) {
        const double dx = i - centre_voxel.x, dy = j - centre_voxel.y, dz = (k - centre_voxel.z) / 3.0;
        v.at(i, j, k) += peak * static_cast<float>(std::exp(-(dx * dx + dy * dy + dz * dz) / (2 * s * s)));
      }
}

TEST(Droplets, FindsEachBlobWithItsPositionAndAnEquivalentDiameterThatFollowsItsSize) {
  DenseVolume v(VoxelGrid::centred(48, 40, 48, 0.02));
  add_blob(v, {12, 12, 20}, 1.5, 100.0f);
  add_blob(v, {32.3, 26.6, 28.2}, 3.0, 60.0f);
  DropletDetectionOptions o;
  o.max_radius_voxel = 6;
  const std::vector<DetectedDroplet> found = detect_droplets(v, o);
  ASSERT_EQ(found.size(), 2u);
  const DetectedDroplet& small = found[0].peak > found[1].peak ? found[0] : found[1];
  const DetectedDroplet& large = found[0].peak > found[1].peak ? found[1] : found[0];
  const Vec3d small_truth = v.grid.centre_of(12, 12, 20), large_truth = v.grid.centre_of(32.3, 26.6, 28.2);
  EXPECT_LT((small.world - small_truth).norm(), 0.2 * 0.02);
  EXPECT_LT((large.world - large_truth).norm(), 0.5 * 0.02);
  // Half-maximum discs of radius 1.5 and 3 voxels: diameters of ~3 and ~6 voxels (0.06, 0.12 mm),
  // within a voxel's quantisation.
  EXPECT_NEAR(small.d_eq_mm, 0.06, 0.02);
  EXPECT_NEAR(large.d_eq_mm, 0.12, 0.02);
  EXPECT_GT(large.d_eq_mm, 1.6 * small.d_eq_mm);
}

TEST(Droplets, FaintBlobsBelowTheRelativeThresholdAreNotDroplets) {
  DenseVolume v(VoxelGrid::centred(32, 32, 32, 0.02));
  add_blob(v, {10, 10, 10}, 1.5, 100.0f);
  add_blob(v, {22, 22, 22}, 1.5, 3.0f);  // 3 % of the brightest
  EXPECT_EQ(detect_droplets(v, {}).size(), 1u);  // default 5 %
  DropletDetectionOptions o;
  o.relative_peak_threshold = 0.01;
  EXPECT_EQ(detect_droplets(v, o).size(), 2u);
  o.relative_peak_threshold = 1.5;
  EXPECT_THROW(detect_droplets(v, o), Error);
}

}  // namespace
}  // namespace tomorig::particles
