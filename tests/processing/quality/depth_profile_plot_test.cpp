// Intensity against depth of a reconstruction, as `reconstruct --png` draws it (issue 23).
#include "tomorig/processing/quality/depth_profile_plot.h"

#include <gtest/gtest.h>

#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

TEST(DepthProfilePlot, MeanIntensityPerSliceAveragesOverTheWholeSlice) {
  SparseVolume v;
  v.grid.nx = 4;
  v.grid.ny = 5;
  v.grid.nz = 3;
  v.grid.voxel_size = 0.1;
  // Slice 0: two voxels of 10; slice 2: one voxel of 40; slice 1 empty.
  v.index = {0, 7, 2 * 20 + 3};
  v.intensity = {10.f, 10.f, 40.f};
  const std::vector<double> mean = mean_intensity_per_slice(v);
  ASSERT_EQ(mean.size(), 3u);
  EXPECT_DOUBLE_EQ(mean[0], 20.0 / 20.0);
  EXPECT_DOUBLE_EQ(mean[1], 0.0);
  EXPECT_DOUBLE_EQ(mean[2], 40.0 / 20.0);
}

TEST(DepthProfilePlot, DrawsEachCurveWhereItsValuesAre) {
  // A curve that is 0 except a peak in the middle: the plot is dark high up in the middle only.
  DepthCurve c{"A", {}, {}};
  for (int k = 0; k < 21; ++k) {
    c.z_mm.push_back(-1.0 + 0.1 * k);
    c.values.push_back(k == 10 ? 1.0 : 0.0);
  }
  const Image image = depth_profile_plot({c}, "test");
  ASSERT_GT(image.width(), 0);
  const auto dark_in_column = [&](int x, int y0, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y) n += image.row<std::uint8_t>(y)[x] < 100;
    return n;
  };
  // The upper half of the plot area (rows 60-200 of 480): crossed by the peak near the centre
  // column (x = 90 + 600 / 2 = 390), empty near the left and right quarters.
  EXPECT_GT(dark_in_column(390, 60, 200), 0);
  EXPECT_EQ(dark_in_column(240, 60, 200), 0);
  EXPECT_EQ(dark_in_column(540, 60, 200), 0);
  EXPECT_THROW(depth_profile_plot({}, "none"), Error);
  EXPECT_THROW(depth_profile_plot({DepthCurve{"B", {0.0}, {}}}, "bad"), Error);
}

}  // namespace
}  // namespace tomorig::quality
