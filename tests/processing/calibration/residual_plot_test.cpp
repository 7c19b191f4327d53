// The residual picture of a calibration (issue 23): one point displaced by a known amount must
// carry the one visible arrow, pointing from the detected point to where the model projects
// it, and the figures written on it must be the known residuals.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/calibration/residual_plot.h"

namespace tomorig::calibration {
namespace {

TEST(ResidualPlot, TheOneDisplacedPointCarriesTheOneArrowAndTheFiguresAreItsResidual) {
  const PinholeCamera camera = PinholeCamera::yawed(20, 60, 10, 600, 512, 512);
  std::vector<PointCorrespondence> points;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const Vec3d world{-8.0 + 4.0 * i, -8.0 + 4.0 * j, 0.0};
      points.push_back({world, camera.project(world)});
    }
  const std::size_t moved = 12;  // the centre point, detected 6 px to the right of its projection
  points[moved].pixel.x += 6.0;

  const ResidualPlot plot = residual_plot(camera, points, {512, 512}, "camera 0, plane z = 0 mm");
  EXPECT_NEAR(plot.max_px, 6.0, 1e-9);
  EXPECT_NEAR(plot.rms_px, 6.0 / std::sqrt(25.0), 1e-9);
  EXPECT_GE(plot.magnification, 1.0);
  EXPECT_EQ(plot.image.width(), 512);
  EXPECT_EQ(plot.image.height(), 512 + 40);  // the image area under a 40-pixel legend

  // Halfway along the arrow (it points left, towards the projection) the picture is dark; the
  // same distance left of an undisplaced point it is white: no arrow there.
  const auto pixel = [&](double x, double y) {
    return plot.image.at<std::uint8_t>(static_cast<int>(std::lround(x)), 40 + static_cast<int>(std::lround(y)));
  };
  const double half = 0.5 * plot.magnification * 6.0;
  const Vec2d p = points[moved].pixel;
  EXPECT_LT(pixel(p.x - half, p.y), 128) << "the arrow of the displaced point";
  const Vec2d q = points[0].pixel;
  EXPECT_EQ(pixel(q.x - half, q.y), 255) << "no arrow at an exact point";
}

TEST(ResidualPlot, NoPointsOrNoImageIsRefused) {
  const PinholeCamera camera = PinholeCamera::yawed(0, 60, 10, 600, 512, 512);
  const std::vector<PointCorrespondence> none;
  EXPECT_THROW(residual_plot(camera, none, {512, 512}, "empty"), Error);
  const std::vector<PointCorrespondence> one{{{0, 0, 0}, camera.project({0, 0, 0})}};
  EXPECT_THROW(residual_plot(camera, one, {0, 512}, "no image"), Error);
}

}  // namespace
}  // namespace tomorig::calibration
