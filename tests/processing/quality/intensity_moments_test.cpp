// Where a volume's intensity lies (quality/intensity_moments.h): centroid and mass quantiles of
// volumes whose answer is known in closed form.
#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/quality/intensity_moments.h"

namespace tomorig::quality {
namespace {

TEST(IntensityMoments, AUniformSlabHasItsCentreAndItsQuantilesWhereTheSlabIs) {
  VoxelGrid g{20, 10, 8, {-1.0, 2.0, 0.5}, 0.1};
  DenseVolume v(g);
  // A slab filling x voxels 5..14 (world -0.55 .. 0.45 mm, voxel edges), every y and z.
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 5; i < 15; ++i) v.at(i, j, k) = 2.0f;
  v.at(0, 0, 0) = -5.0f;  // negative intensities carry no mass
  const IntensityMoments m = intensity_moments(v, 0.1);
  EXPECT_DOUBLE_EQ(m.mass, 2.0 * 10 * 10 * 8);
  EXPECT_FLOAT_EQ(m.max, 2.0f);
  EXPECT_NEAR(m.centroid_mm.x, -1.0 + 9.5 * 0.1, 1e-9);
  EXPECT_NEAR(m.centroid_mm.y, 2.0 + 4.5 * 0.1, 1e-9);
  EXPECT_NEAR(m.low_mm.x, -1.0 + 4.5 * 0.1 + 0.1, 1e-9);   // 10 % of 1 mm in from the slab's edge
  EXPECT_NEAR(m.median_mm.x, -1.0 + 9.5 * 0.1, 1e-9);
  EXPECT_NEAR(m.high_mm.x, -1.0 + 14.5 * 0.1 - 0.1, 1e-9);
  EXPECT_NEAR(m.low_mm.z, 0.5 - 0.05 + 0.08, 1e-9);        // the full depth of 0.8 mm
}

TEST(IntensityMoments, AnEmptyVolumeHasNoMassAndBadTailsAreRefused) {
  DenseVolume v(VoxelGrid{4, 4, 4, {}, 1.0});
  EXPECT_EQ(intensity_moments(v).mass, 0.0);
  EXPECT_THROW(intensity_moments(v, 0.5), Error);
  EXPECT_THROW(intensity_moments(v, 0.0), Error);
}

}  // namespace
}  // namespace tomorig::quality
