// The vector-slice picture of `process --png` (issue 23): cells shaded by magnitude with a colour
// bar that matches them, arrows along the displacement, invalid nodes black, axes and a scale.
#include "tomorig/processing/quicklook/vector_slice_plot.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

std::uint8_t at(const Image& image, int x, int y) { return image.row<std::uint8_t>(y)[x]; }

// A 6 x 4 slice: displacement (i, 0) voxel, node (0, 0) without a valid vector.
VectorSlice ramp() {
  VectorSlice s;
  s.nx = 6;
  s.ny = 4;
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      s.displacement.push_back({static_cast<double>(i), 0.0, 0.0});
      s.valid.push_back(!(i == 0 && j == 0));
    }
  return s;
}

TEST(VectorSlicePlot, ShadesCellsByMagnitudeAsTheColourBarSays) {
  VectorSliceLayout l;
  const Image image = vector_slice_plot(ramp(), &l);
  ASSERT_GT(l.cell, 0);
  // Node (i, j) is drawn with row j = 0 at the bottom; sample a cell corner, away from its arrow.
  const auto cell = [&](int i, int j) { return at(image, l.plot_left + i * l.cell + 1, l.plot_top + (3 - j) * l.cell + 1); };
  EXPECT_EQ(cell(0, 0), 0) << "no valid vector: black";
  EXPECT_EQ(cell(5, 2), 255) << "the largest magnitude: white";
  for (int i = 1; i < 5; ++i) EXPECT_LT(cell(i, 1), cell(i + 1, 1)) << i;
  // The colour bar runs from the smallest grey at 0 (bottom) to white at the largest (top), and
  // its grey at magnitude 2 (of 5) is the grey of node (2, *).
  const int bar_x = l.bar_left + l.bar_width / 2;
  EXPECT_EQ(at(image, bar_x, l.bar_top), 255);
  EXPECT_LT(at(image, bar_x, l.bar_top + l.bar_height - 1), 60);
  const int y2 = l.bar_top + l.bar_height - 1 - static_cast<int>(std::lround(2.0 / 5.0 * (l.bar_height - 1)));
  EXPECT_NEAR(at(image, bar_x, y2), cell(2, 3), 2);
}

TEST(VectorSlicePlot, DrawsArrowsAlongTheDisplacement) {
  // One valid node, (2, 1), moving 3 voxel along +y (up on the plot): dark pixels above its
  // centre, none below or to the sides.
  VectorSlice s;
  s.nx = 5;
  s.ny = 3;
  s.displacement.assign(15, Vec3d{0.0, 0.0, 0.0});
  s.valid.assign(15, false);
  s.displacement[2 + 5 * 1] = {0.0, 3.0, 0.0};
  s.valid[2 + 5 * 1] = true;
  VectorSliceLayout l;
  const Image image = vector_slice_plot(s, &l);
  const int cx = l.plot_left + 2 * l.cell + l.cell / 2, cy = l.plot_top + 1 * l.cell + l.cell / 2;
  int up = 0, down = 0, side = 0;
  for (int d = 3; d < l.cell / 2 - 1; ++d) {
    up += at(image, cx, cy - d) < 128;
    down += at(image, cx, cy + d) < 128;
    side += (at(image, cx - d, cy) < 128) + (at(image, cx + d, cy) < 128);
  }
  EXPECT_GT(up, 0);
  EXPECT_EQ(down, 0);
  EXPECT_EQ(side, 0);
}

TEST(VectorSlicePlot, RefusesMismatchedArrays) {
  VectorSlice s = ramp();
  s.valid.pop_back();
  EXPECT_THROW(vector_slice_plot(s), Error);
  EXPECT_THROW(vector_slice_plot(VectorSlice{}), Error);
}

}  // namespace
}  // namespace tomorig::quicklook
