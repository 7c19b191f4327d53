// The calib-thesis simulator: geometry and truth as the benchmark describes them, seeded and
// reproducible renders, and a rendered corner where the true camera puts it.
#include <cmath>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/calibration_target.h"

namespace tomorig::sim {
namespace {

CalibTargetOptions reduced(std::uint64_t seed = 2) {
  CalibTargetOptions o;
  o.reduced = true;
  o.seed = seed;
  return o;
}

TEST(CalibTarget, CaseMatchesTheBenchmarkDescription) {
  const CalibTargetCase c = make_calib_thesis_case(reduced());
  EXPECT_EQ(c.board.inner_corners_x, 22);
  EXPECT_EQ(c.board.inner_corners_y, 21);
  EXPECT_DOUBLE_EQ(c.board.square_mm, 0.75);
  ASSERT_EQ(c.planes.size(), 7u);
  for (std::size_t k = 0; k < 7; ++k) EXPECT_NEAR(c.planes[k].z_nominal_mm, -4.5 + 1.5 * k, 1e-12);
  ASSERT_EQ(c.cameras.size(), 4u);
  const double yaws[] = {-45, -20, 25, 45};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(c.cameras[i].yaw_deg, yaws[i]);
    EXPECT_EQ(c.cameras[i].width, 640);
    EXPECT_EQ(c.cameras[i].height, 540);
    // Magnification ~0.9 at the board centre: one square (0.75 mm) spans ~0.9 * 0.75 mm of sensor
    // along y (the yaw foreshortens x only).
    const Vec2d a = c.corner_pixel(i, 10, 9, 3), b = c.corner_pixel(i, 10, 11, 3);
    const double m = std::hypot(b.x - a.x, b.y - a.y) * c.cameras[i].pixel_pitch_um * 1e-3 / (2 * 0.75);
    EXPECT_NEAR(m, 0.9, 0.03) << "camera " << i + 1;
  }
  // Stage errors of Table 6.3's size: within +-2/8/22 um, and not all tiny.
  double largest_z = 0;
  for (const TargetPlane& p : c.planes) {
    EXPECT_LE(std::abs(p.offset_mm.x), 0.002);
    EXPECT_LE(std::abs(p.offset_mm.y), 0.008);
    EXPECT_LE(std::abs(p.offset_mm.z), 0.022);
    largest_z = std::max(largest_z, std::abs(p.offset_mm.z));
  }
  EXPECT_GT(largest_z, 0.005);
  // Seeded: same seed, same errors; another seed, others.
  const CalibTargetCase same = make_calib_thesis_case(reduced()), other = make_calib_thesis_case(reduced(3));
  EXPECT_EQ(same.planes[2].offset_mm.z, c.planes[2].offset_mm.z);
  EXPECT_NE(other.planes[2].offset_mm.z, c.planes[2].offset_mm.z);
}

TEST(CalibTarget, DistortionRoundTripsAndProjectionsAgree) {
  const CalibTargetCase c = make_calib_thesis_case(reduced());
  const TargetCamera& cam = c.cameras[0];
  EXPECT_NE(cam.k1, 0.0);
  const Vec2d u{37.25, 501.5};
  const Vec2d back = cam.undistort(cam.distort(u));
  EXPECT_NEAR(back.x, u.x, 1e-9);
  EXPECT_NEAR(back.y, u.y, 1e-9);
  const Vec3d w = c.corner_world(3, 4, 1);
  const Vec3d again = cam.back_project(cam.project(w), w.z);
  EXPECT_NEAR((again - w).norm(), 0.0, 1e-9);
}

TEST(CalibTarget, RenderIsReproducibleAndCornersSitWhereTheTruthSays) {
  CalibTargetOptions o = reduced();
  o.noise = false;
  const CalibTargetCase c = make_calib_thesis_case(o);
  const Image a = render_target_view(c, 1, 3), b = render_target_view(c, 1, 3);
  EXPECT_EQ(a.type(), SampleType::u16);
  EXPECT_TRUE(a.same_pixels(b));
  // Point symmetry of an X-corner: pixels mirrored through the true corner position have the
  // same grey level only if the corner really is there (checked on the noise-free render by
  // sampling bilinearly at +-d around it, along both image axes and a diagonal).
  const Vec2d p = c.corner_pixel(1, 11, 10, 3);
  auto sample = [&](double x, double y) {
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    return (1 - fy) * ((1 - fx) * a.value(x0, y0) + fx * a.value(x0 + 1, y0)) +
           fy * ((1 - fx) * a.value(x0, y0 + 1) + fx * a.value(x0 + 1, y0 + 1));
  };
  const double contrast = o.light_counts - o.dark_counts;
  for (const Vec2d d : {Vec2d{3, 1}, Vec2d{1, 3}, Vec2d{2.5, -2}}) {
    const double plus = sample(p.x + d.x, p.y + d.y), minus = sample(p.x - d.x, p.y - d.y);
    EXPECT_LT(std::abs(plus - minus), 0.05 * contrast) << d.x << "," << d.y;
  }
  // And the two diagonals differ (it is a chessboard corner, not a flat patch).
  EXPECT_GT(std::abs(sample(p.x + 3, p.y + 3) - sample(p.x + 3, p.y - 3)), 0.5 * contrast);
}

TEST(CalibTarget, RefusesBadOptions) {
  CalibTargetOptions o = reduced();
  o.stage_error_scale = -1;
  EXPECT_THROW(make_calib_thesis_case(o), Error);
  o = reduced();
  o.light_counts = 100;  // darker than the dark squares
  EXPECT_THROW(make_calib_thesis_case(o), Error);
  o = reduced();
  o.blur_sigma_px = NAN;
  EXPECT_THROW(make_calib_thesis_case(o), Error);
}

}  // namespace
}  // namespace tomorig::sim
