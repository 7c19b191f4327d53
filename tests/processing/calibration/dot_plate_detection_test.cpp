// Dot plates rendered by the simulator (sim::render_dot_plate): staggered lattices, two depth
// levels, filled square and triangle markers. Every detected dot's world point (lattice index
// and level) must project through the true camera onto the detected pixel within 0.05 px; a
// wrong index or level is off by a pitch or by the parallax between the levels (several px).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <string>

#include "dot_grid_render.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/simulators/dot_target.h"

namespace {

using namespace dot_grid_test;
using tomorig::calibration::DotLattice;
using tomorig::calibration::PinholeCamera;
using tomorig::calibration::TargetDetection;
using tomorig::calibration::detect_dot_grid;

constexpr int kWidth = 400, kHeight = 320;

tomorig::sim::DotPlate staggered_plate(double level_offset_mm) {
  tomorig::sim::DotPlate plate;
  plate.spec.spacing_mm = 2.0;
  plate.spec.lattice = DotLattice::staggered;
  plate.spec.level_offset_mm = level_offset_mm;
  plate.dot_radius_mm = 0.25;
  plate.triangle_site = 2;
  plate.noise_counts = 8;
  return plate;
}

double worst_error(const PinholeCamera& camera, const TargetDetection& d) {
  double worst = 0;
  for (const auto& p : d.points) {
    const Vec2d truth = camera.project(p.world);
    worst = std::max(worst, std::hypot(truth.x - p.pixel.x, truth.y - p.pixel.y));
  }
  return worst;
}

// Dots of the plate (both levels) whose image lies well inside the picture.
int visible_dots(const PinholeCamera& camera, const tomorig::sim::DotPlate& plate, double z) {
  const double s = plate.spec.spacing_mm;
  int count = 0;
  for (int level = 0; level < 2; ++level)
    for (int i = -plate.half_extent; i <= plate.half_extent; ++i)
      for (int j = -plate.half_extent; j <= plate.half_extent; ++j) {
        if (level == 0 && ((i == 0 && j == 0) || (i == plate.triangle_site && j == 0))) continue;  // markers
        const double shift = level ? 0.5 * s : 0;
        const Vec2d p = camera.project({i * s + shift, j * s + shift, z + (level ? plate.spec.level_offset_mm : 0)});
        if (p.x > 8 && p.y > 8 && p.x < kWidth - 9 && p.y < kHeight - 9) ++count;
      }
  return count;
}

TEST(DotPlateDetection, StaggeredTwoLevelPlateEveryDotLabelledAndLevelsResolved) {
  for (const double offset : {0.5, -0.6}) {
    const PinholeCamera camera = oblique_camera(28, 8, 3, 15, 300, kWidth, kHeight);
    const auto plate = staggered_plate(offset);
    const double z = 1.0;
    const TargetDetection d = detect_dot_grid(tomorig::sim::render_dot_plate(camera, plate, z, kWidth, kHeight), plate.spec,
                                              z, "camera 0, plane z = 1 mm");
    const int visible = visible_dots(camera, plate, z);
    EXPECT_GE(static_cast<int>(d.points.size()), visible) << "offset " << offset;
    EXPECT_LT(worst_error(camera, d), 0.05) << "offset " << offset;
    std::set<double> levels;
    int second = 0;
    for (const auto& p : d.points) {
      levels.insert(p.world.z);
      // The second level's dots sit at the cell centres, on it and only there.
      const bool centre = std::abs(std::fmod(std::abs(p.world.x), 2.0) - 1.0) < 1e-9;
      EXPECT_EQ(centre, p.world.z != z) << p.world.x << ", " << p.world.y << ", " << p.world.z;
      second += p.world.z == z + offset;
    }
    EXPECT_EQ(levels, (std::set<double>{z, z + offset}));
    EXPECT_GT(second, visible / 3);
    // The origin and the axes, from the filled square and the triangle.
    EXPECT_TRUE(d.axis_marker);
    EXPECT_EQ(d.origin_marker, "filled square");
    ASSERT_TRUE(d.origin_px && d.x_step_px);
    const Vec2d o = camera.project({0, 0, z}), ox = camera.project({2, 0, z});
    EXPECT_LT(std::hypot(d.origin_px->x - o.x, d.origin_px->y - o.y), 0.5);
    EXPECT_LT(std::hypot(d.x_step_px->x - (ox.x - o.x), d.x_step_px->y - (ox.y - o.y)), 0.5);
  }
}

// The triangle fixes +x even when the camera is rolled so far that "most nearly to the right"
// would pick another lattice direction.
TEST(DotPlateDetection, TriangleFixesTheAxesOfARolledView) {
  const PinholeCamera camera = oblique_camera(-20, 5, 120, 15, 300, kWidth, kHeight);
  auto plate = staggered_plate(0.4);
  const TargetDetection d =
      detect_dot_grid(tomorig::sim::render_dot_plate(camera, plate, 0, kWidth, kHeight), plate.spec, 0, "rolled");
  ASSERT_GT(d.points.size(), 100u);
  // y follows the image (down) as the spec says; x is the triangle's, so the result may be
  // mirrored in y against the plate, never turned: x must match.
  for (const auto& p : d.points) {
    const Vec2d truth = camera.project(p.world), mirrored = camera.project({p.world.x, -p.world.y, p.world.z});
    EXPECT_LT(std::min(std::hypot(truth.x - p.pixel.x, truth.y - p.pixel.y),
                       std::hypot(mirrored.x - p.pixel.x, mirrored.y - p.pixel.y)),
              0.05);
  }
}

TEST(DotPlateDetection, SquareLatticeWithFilledMarkers) {
  const PinholeCamera camera = oblique_camera(25, -6, 2, 15, 300, kWidth, kHeight);
  tomorig::sim::DotPlate plate;
  plate.spec.spacing_mm = 1.5;
  plate.dot_radius_mm = 0.2;
  plate.triangle_site = 3;
  plate.noise_counts = 8;
  const TargetDetection d =
      detect_dot_grid(tomorig::sim::render_dot_plate(camera, plate, -2, kWidth, kHeight), plate.spec, -2, "square");
  EXPECT_GT(d.points.size(), 200u);
  EXPECT_LT(worst_error(camera, d), 0.05);
  EXPECT_TRUE(d.axis_marker);
}

void expect_bad_input(const std::function<void()>& f, const std::vector<std::string>& needles) {
  try {
    f();
    ADD_FAILURE() << "no error";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
  }
}

// A staggered plate described as a square lattice (--spacing alone) is named, not scaled by
// sqrt(2): by the triangle on a diagonal, or without a triangle by the two levels' parallax.
TEST(DotPlateDetection, StaggeredPlateReadAsSquareIsRefusedWithTheReason) {
  const PinholeCamera camera = oblique_camera(28, 8, 3, 15, 300, kWidth, kHeight);
  auto plate = staggered_plate(0.5);
  auto as_square = plate.spec;
  as_square.lattice = DotLattice::square;
  as_square.level_offset_mm = 0;
  as_square.spacing_mm = 2.0;
  const tomorig::Image with_triangle = tomorig::sim::render_dot_plate(camera, plate, 0, kWidth, kHeight);
  expect_bad_input([&] { detect_dot_grid(with_triangle, as_square, 0, "camera 0"); },
                   {"camera 0", "diagonal", "staggered", "sqrt(2)", "--lattice staggered"});
  plate.triangle_site = 0;
  const tomorig::Image without = tomorig::sim::render_dot_plate(camera, plate, 0, kWidth, kHeight);
  expect_bad_input([&] { detect_dot_grid(without, as_square, 0, "camera 0"); },
                   {"two interleaved sub-lattices", "two depth levels", "sqrt(2)", "--level-offset"});
}

TEST(DotPlateDetection, TwoOriginMarkersAreNamedWithTheirPositions) {
  const PinholeCamera camera = oblique_camera(10, 0, 0, 15, 300, kWidth, kHeight);
  auto plate = staggered_plate(0.0);
  plate.spec.origin_mm = {0, 0, 0};
  tomorig::Image a = tomorig::sim::render_dot_plate(camera, plate, 0, kWidth, kHeight);
  // A second plate's origin square in view: paste the plate shifted by 4 pitches.
  plate.spec.origin_mm = {8, 4, 0};
  const tomorig::Image b = tomorig::sim::render_dot_plate(camera, plate, 0, kWidth, kHeight);
  for (int v = 0; v < kHeight; ++v)
    for (int u = 0; u < kWidth; ++u) a.at<std::uint16_t>(u, v) = std::max(a.at<std::uint16_t>(u, v), b.at<std::uint16_t>(u, v));
  expect_bad_input([&] { detect_dot_grid(a, staggered_plate(0.0).spec, 0, "cam"); }, {"2 origin markers", "filled square at ("});
}

}  // namespace
