// Normalisation of point correspondences (thesis Appendix A.1, Eq. A.1), checked against
// its definition: centroids at the origin, mean distances sqrt(3) (world) and sqrt(2) (image).
#include <cmath>

#include <gtest/gtest.h>

#include "synthetic_points.h"
#include "tomorig/core/error.h"

namespace {

using namespace calib_test;
using tomorig::calibration::compute_normalization;

TEST(Normalization, CentroidAtTheOriginAndMeanDistancesOfTheAveragePoint) {
  Truth truth;
  auto points = grid_points(truth, {1.0, 2.5, 4.0}, 6, 3.0, 0.3, 8);
  for (auto& p : points) p.world = p.world + Vec3d{10, -20, 0};  // off-centre on purpose
  const auto n = compute_normalization(points);
  Vec3d world_sum;
  double image_sum_x = 0, image_sum_y = 0, world_dist = 0, image_dist = 0;
  for (const auto& p : points) {
    const Vec3d w = n.to_normalised(p.world);
    const Vec2d i = n.to_normalised(p.pixel);
    world_sum = world_sum + w;
    image_sum_x += i.x;
    image_sum_y += i.y;
    world_dist += w.norm() / points.size();
    image_dist += std::hypot(i.x, i.y) / points.size();
    // The inverse maps back.
    const Vec3d back = n.to_world(w);
    EXPECT_NEAR((back - p.world).norm(), 0.0, 1e-12);
  }
  EXPECT_NEAR(world_sum.norm(), 0.0, 1e-9);
  EXPECT_NEAR(std::hypot(image_sum_x, image_sum_y), 0.0, 1e-9);
  EXPECT_NEAR(world_dist, std::sqrt(3.0), 1e-12);
  EXPECT_NEAR(image_dist, std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(n.world_centre.x, 10.0, 1e-12);
  EXPECT_NEAR(n.world_centre.z, 2.5, 1e-12);
}

TEST(Normalization, CoincidentPointsCannotBeNormalised) {
  std::vector<PointCorrespondence> same(5, PointCorrespondence{{1, 2, 3}, {4, 5}});
  EXPECT_THROW(compute_normalization(same), tomorig::Error);
  EXPECT_THROW(compute_normalization({}), tomorig::Error);
}

}  // namespace
