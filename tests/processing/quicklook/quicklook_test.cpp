// Quick-look images: the percentile stretch and maximum-intensity projections of volumes.
#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/display.h"

namespace tomorig::quicklook {
namespace {

TEST(Stretch, MapsPercentilesToBlackAndWhite) {
  // A 100 x 10 ramp 0..999 in u16: the 1st percentile (10) maps to 0, the 99.9th (998) to 255.
  Image ramp = Image::allocate(100, 10, SampleType::u16);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 100; ++x) ramp.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(y * 100 + x);
  const Image out = stretch_to_8bit(ramp);
  ASSERT_EQ(out.type(), SampleType::u8);
  ASSERT_EQ(out.width(), 100);
  ASSERT_EQ(out.height(), 10);
  EXPECT_EQ(out.at<std::uint8_t>(0, 0), 0);
  EXPECT_EQ(out.at<std::uint8_t>(10, 0), 0);
  EXPECT_EQ(out.at<std::uint8_t>(99, 9), 255);
  // Linear in between: value 504 lies halfway between 10 and 998.
  EXPECT_NEAR(out.at<std::uint8_t>(4, 5), 127.5, 1.0);
}

TEST(Stretch, HotPixelDoesNotWashOutTheImage) {
  Image img = Image::allocate(100, 100, SampleType::u16);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 100; ++x) img.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>((x + y) % 50);
  img.at<std::uint16_t>(3, 3) = 65535;
  const Image out = stretch_to_8bit(img);
  // The brightest ordinary pixels (49) are near white, not crushed to ~0 by the hot pixel.
  EXPECT_GT(out.at<std::uint8_t>(49, 0), 240);
  EXPECT_EQ(out.at<std::uint8_t>(3, 3), 255);
}

TEST(Stretch, FlatAndFloatImages) {
  Image flat = Image::allocate(8, 8, SampleType::u8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) flat.at<std::uint8_t>(x, y) = 77;
  const Image out = stretch_to_8bit(flat);
  EXPECT_EQ(out.at<std::uint8_t>(4, 4), 0);
  Image f = Image::allocate(4, 1, SampleType::f32);
  f.at<float>(0, 0) = NAN;
  f.at<float>(1, 0) = 0.0f;
  f.at<float>(2, 0) = 0.5f;
  f.at<float>(3, 0) = 1.0f;
  const Image g = stretch_to_8bit(f, {0.0, 100.0});
  EXPECT_EQ(g.at<std::uint8_t>(0, 0), 0);  // NaN counts as 0
  EXPECT_NEAR(g.at<std::uint8_t>(2, 0), 128, 1);
  EXPECT_EQ(g.at<std::uint8_t>(3, 0), 255);
}

TEST(Stretch, BadPercentilesAreRefused) {
  const Image img = Image::allocate(2, 2, SampleType::u8);
  EXPECT_THROW(stretch_to_8bit(img, {50.0, 50.0}), Error);
  EXPECT_THROW(stretch_to_8bit(img, {-1.0, 50.0}), Error);
  EXPECT_THROW(stretch_to_8bit(Image(), {}), Error);
}

TEST(MaxProjection, SparseAndDenseAgreeAndPickTheMaximumAlongEachAxis) {
  const VoxelGrid grid{5, 4, 3, {0, 0, 0}, 1.0};
  SparseVolume sparse;
  sparse.grid = grid;
  // (i, j, k) -> value; two voxels share (i, j) = (1, 2) at different k.
  const struct { int i, j, k; float v; } voxels[] = {{1, 2, 0, 3.0f}, {4, 0, 1, 1.0f}, {1, 2, 2, 5.0f}};
  for (const auto& v : voxels) {
    sparse.index.push_back(static_cast<std::uint32_t>(grid.linear(v.i, v.j, v.k)));
    sparse.intensity.push_back(v.v);
  }
  const DenseVolume dense = sparse.to_dense();
  for (const Axis axis : {Axis::x, Axis::y, Axis::z}) {
    const Image a = max_projection(sparse, axis), b = max_projection(dense, axis);
    ASSERT_EQ(a.width(), b.width());
    ASSERT_EQ(a.height(), b.height());
    for (int y = 0; y < a.height(); ++y)
      for (int x = 0; x < a.width(); ++x) EXPECT_EQ(a.at<float>(x, y), b.at<float>(x, y));
  }
  const Image z = max_projection(sparse, Axis::z);
  EXPECT_EQ(z.width(), 5);
  EXPECT_EQ(z.height(), 4);
  EXPECT_EQ(z.at<float>(1, 2), 5.0f);
  EXPECT_EQ(z.at<float>(4, 0), 1.0f);
  EXPECT_EQ(z.at<float>(0, 0), 0.0f);
  const Image y = max_projection(sparse, Axis::y);  // nx x nz
  EXPECT_EQ(y.width(), 5);
  EXPECT_EQ(y.height(), 3);
  EXPECT_EQ(y.at<float>(1, 0), 3.0f);
  EXPECT_EQ(y.at<float>(1, 2), 5.0f);
  const Image x = max_projection(sparse, Axis::x);  // ny x nz
  EXPECT_EQ(x.width(), 4);
  EXPECT_EQ(x.at<float>(2, 2), 5.0f);
  EXPECT_EQ(x.at<float>(0, 1), 1.0f);
}

TEST(MaxProjection, MalformedVolumesAreRefused) {
  SparseVolume bad;
  bad.grid = {2, 2, 2, {0, 0, 0}, 1.0};
  bad.index = {9};
  bad.intensity = {1.0f};
  EXPECT_THROW(max_projection(bad, Axis::z), Error);
  bad.intensity.clear();
  EXPECT_THROW(max_projection(bad, Axis::z), Error);
}

}  // namespace
}  // namespace tomorig::quicklook
