#include "tomorig/core/volume.h"
#include "tomorig/core/vector_field.h"

#include <gtest/gtest.h>

namespace tomorig {
namespace {

TEST(VoxelGrid, CentredGridMatchesBenchmarkDefinition) {
  // benchmarks/README: voxel (i, j, k) centre at ((i-255.5)*0.0195, (j-255.5)*0.0195, (k-79.5)*0.0195).
  VoxelGrid g = VoxelGrid::centred(512, 512, 160, 0.0195);
  for (int i : {0, 100, 511})
    for (int k : {0, 80, 159}) {
      Vec3d c = g.centre_of(i, 7, k);
      EXPECT_NEAR(c.x, (i - 255.5) * 0.0195, 1e-12);
      EXPECT_NEAR(c.y, (7 - 255.5) * 0.0195, 1e-12);
      EXPECT_NEAR(c.z, (k - 79.5) * 0.0195, 1e-12);
      Vec3d v = g.voxel_of(c);
      EXPECT_NEAR(v.x, i, 1e-9);
      EXPECT_NEAR(v.z, k, 1e-9);
    }
  EXPECT_EQ(g.voxel_count(), 512u * 512u * 160u);
  EXPECT_EQ(g.linear(1, 2, 3), 1u + 512u * (2u + 512u * 3u));
}

TEST(SparseVolume, ToDensePlacesIntensities) {
  SparseVolume s;
  s.grid = VoxelGrid::centred(4, 3, 2, 1.0);
  s.index = {0, static_cast<std::uint32_t>(s.grid.linear(3, 2, 1))};
  s.intensity = {1.5f, 2.5f};
  DenseVolume d = s.to_dense();
  EXPECT_EQ(d.at(0, 0, 0), 1.5f);
  EXPECT_EQ(d.at(3, 2, 1), 2.5f);
  float sum = 0;
  for (float v : d.values) sum += v;
  EXPECT_FLOAT_EQ(sum, 4.0f);
}

TEST(VectorField, StartsInvalidWithOneEntryPerNode) {
  VectorField f(3, 4, 5);
  EXPECT_EQ(f.count(), 60u);
  EXPECT_EQ(f.displacement.size(), 60u);
  EXPECT_EQ(f.status[f.linear(2, 3, 4)], VectorStatus::invalid);
}

}  // namespace
}  // namespace tomorig
