// Dot-grid detection against images rendered from a known camera: every detected dot's world
// position (from its lattice index) must project, through the true camera, onto the detected
// pixel to within 0.1 px. A wrong index would be off by a whole spacing (~30 px).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "dot_grid_render.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace {

using namespace dot_grid_test;
using tomorig::calibration::DotGridSpec;
using tomorig::calibration::PinholeCamera;
using tomorig::calibration::TargetDetection;

constexpr int kWidth = 360, kHeight = 320;

// Largest distance between a detected pixel and the true projection of its world point.
double worst_error(const PinholeCamera& camera, const TargetDetection& d) {
  double worst = 0;
  for (const auto& p : d.points) {
    const Vec2d truth = camera.project(p.world);
    worst = std::max(worst, std::hypot(truth.x - p.pixel.x, truth.y - p.pixel.y));
  }
  return worst;
}

bool has_site(const TargetDetection& d, int i, int j, double spacing) {
  return std::any_of(d.points.begin(), d.points.end(), [&](const auto& p) {
    return std::abs(p.world.x - i * spacing) < 1e-9 && std::abs(p.world.y - j * spacing) < 1e-9;
  });
}

// Lattice sites whose dot lies fully inside the image (a margin of 2 dot radii).
int visible_sites(const PinholeCamera& camera, const TargetDrawing& t, double z) {
  int count = 0;
  for (int i = -t.half_extent; i <= t.half_extent; ++i)
    for (int j = -t.half_extent; j <= t.half_extent; ++j) {
      if (t.missing.count({i, j})) continue;
      const Vec2d p = camera.project({t.offset_mm.x + i * t.spacing_mm, t.offset_mm.y + j * t.spacing_mm, z});
      const double margin = 8;
      if (p.x > margin && p.y > margin && p.x < kWidth - 1 - margin && p.y < kHeight - 1 - margin) ++count;
    }
  return count;
}

DotGridSpec spec_for(const TargetDrawing& t) {
  DotGridSpec spec;
  spec.spacing_mm = t.spacing_mm;
  spec.white_dots = t.white_dots;
  return spec;
}

TEST(DotGridDetection, WhiteDotsObliqueViewSubPixelAndCorrectIndices) {
  const PinholeCamera camera = oblique_camera(30, 12, 4, 15, 300, kWidth, kHeight);
  TargetDrawing t;
  t.marker_contrast = 0.05;  // a faint frame, as on the fluidimage target
  const double z = 1.5;
  const TargetDetection d = tomorig::calibration::detect_dot_grid(
      render_target(camera, t, z, kWidth, kHeight, 10), spec_for(t), z, "camera 0, plane z = 1.5 mm");
  EXPECT_GE(static_cast<int>(d.points.size()), visible_sites(camera, t, z) - 2);
  EXPECT_TRUE(has_site(d, 0, 0, t.spacing_mm));
  EXPECT_LT(worst_error(camera, d), 0.1);
  for (const auto& p : d.points) EXPECT_EQ(p.world.z, z);
}

TEST(DotGridDetection, BlackDotsOnWhite) {
  const PinholeCamera camera = oblique_camera(-25, -8, -3, 14, 280, kWidth, kHeight);
  TargetDrawing t;
  t.white_dots = false;
  const double z = -2;
  const TargetDetection d = tomorig::calibration::detect_dot_grid(render_target(camera, t, z, kWidth, kHeight, 10),
                                                                  spec_for(t), z, "camera 1, plane z = -2 mm");
  EXPECT_GE(static_cast<int>(d.points.size()), visible_sites(camera, t, z) - 2);
  EXPECT_TRUE(has_site(d, 0, 0, t.spacing_mm));
  EXPECT_LT(worst_error(camera, d), 0.1);

  // The wrong polarity finds no grid and says so.
  DotGridSpec wrong = spec_for(t);
  wrong.white_dots = true;
  try {
    tomorig::calibration::detect_dot_grid(render_target(camera, t, z, kWidth, kHeight), wrong, z, "camera 1, plane z = -2 mm");
    ADD_FAILURE() << "white-dot detection on a black-dot target did not fail";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("camera 1, plane z = -2 mm"), std::string::npos) << e.what();
  }
}

TEST(DotGridDetection, PartlyVisibleTarget) {
  const PinholeCamera camera = oblique_camera(20, 0, 0, 15, 300, kWidth, kHeight);
  TargetDrawing t;
  t.half_extent = 4;           // a small target ...
  t.offset_mm = {-7.5, 4.0};   // ... off to one side: cut by the image's left and bottom edges
  const double z = 0;
  TargetDetection d = tomorig::calibration::detect_dot_grid(render_target(camera, t, z, kWidth, kHeight, 10), spec_for(t),
                                                            z, "camera 2, plane z = 0 mm");
  const int visible = visible_sites(camera, t, z);
  ASSERT_LT(visible, 81);  // the premise: not the whole target is in view
  EXPECT_GE(static_cast<int>(d.points.size()), visible - 2);
  // World positions are relative to the origin dot, wherever the target sits.
  for (auto& p : d.points) p.world = p.world + Vec3d{t.offset_mm.x, t.offset_mm.y, 0};
  EXPECT_LT(worst_error(camera, d), 0.1);
}

TEST(DotGridDetection, MissingAndAmbiguousDotsAreDroppedNotGuessed) {
  const PinholeCamera camera = oblique_camera(25, 5, 2, 15, 300, kWidth, kHeight);
  TargetDrawing t;
  t.missing = {{2, 1}, {-1, -2}, {0, 3}};
  // A stray dot next to site (3, -1): two candidates for one site.
  t.extra_dots_mm = {{3 * t.spacing_mm + 0.5, -1 * t.spacing_mm + 0.5}};
  const double z = 0.5;
  const TargetDetection d = tomorig::calibration::detect_dot_grid(render_target(camera, t, z, kWidth, kHeight, 10),
                                                                  spec_for(t), z, "camera 3, plane z = 0.5 mm");
  EXPECT_FALSE(has_site(d, 3, -1, t.spacing_mm)) << "the ambiguous site was guessed";
  EXPECT_FALSE(has_site(d, 2, 1, t.spacing_mm));
  EXPECT_TRUE(has_site(d, 3, 1, t.spacing_mm));  // beyond the hole, reached another way
  EXPECT_TRUE(has_site(d, 0, 4, t.spacing_mm));
  EXPECT_LT(worst_error(camera, d), 0.1);
  EXPECT_GE(static_cast<int>(d.points.size()), visible_sites(camera, t, z) - 4);
  bool named = false;
  for (const std::string& w : d.warnings) named |= w.find("(3, -1)") != std::string::npos;
  EXPECT_TRUE(named) << "no warning names the dropped site (3, -1)";
}

TEST(DotGridDetection, AxesFollowTheImageAndYDirectionIsConfigurable) {
  const PinholeCamera camera = oblique_camera(10, 0, 0, 15, 300, kWidth, kHeight);
  TargetDrawing t;
  DotGridSpec spec = spec_for(t);
  const Image image = render_target(camera, t, 0, kWidth, kHeight);
  const TargetDetection down = tomorig::calibration::detect_dot_grid(image, spec, 0, "down");
  spec.y_down = false;
  const TargetDetection up = tomorig::calibration::detect_dot_grid(image, spec, 0, "up");
  ASSERT_EQ(down.points.size(), up.points.size());
  EXPECT_LT(worst_error(camera, down), 0.1);
  // With y up, each pixel carries the mirrored y.
  for (const auto& p : up.points) {
    const Vec2d truth = camera.project({p.world.x, -p.world.y, 0});
    EXPECT_LT(std::hypot(truth.x - p.pixel.x, truth.y - p.pixel.y), 0.1);
  }
}

TEST(DotGridDetection, NoOriginMarkerOrBadSpecIsAClearError) {
  const PinholeCamera camera = oblique_camera(10, 0, 0, 15, 300, kWidth, kHeight);
  TargetDrawing t;
  t.marker_line_mm = 0;  // no frame
  auto expect_bad_input = [](auto&& call, const std::string& needle) {
    try {
      call();
      ADD_FAILURE() << "no error; expected one containing '" << needle << "'";
    } catch (const tomorig::Error& e) {
      EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  const Image image = render_target(camera, t, 0, kWidth, kHeight);
  expect_bad_input([&] { tomorig::calibration::detect_dot_grid(image, spec_for(t), 0, "camera 0, plane z = 0 mm"); },
                   "camera 0, plane z = 0 mm: ");
  expect_bad_input([&] { tomorig::calibration::detect_dot_grid(image, spec_for(t), 0, "cam"); }, "no origin marker");
  DotGridSpec bad;
  bad.spacing_mm = -1;
  expect_bad_input([&] { tomorig::calibration::detect_dot_grid(image, bad, 0, "cam"); }, "spacing");
}

}  // namespace
