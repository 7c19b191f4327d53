// PinholeCamera against an independent evaluation of Eq. 3.11/3.12 written out with plain
// doubles, and against the tpiv-thesis geometry of ../shared/benchmarks/README.md.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace {

using tomorig::Vec2d;
using tomorig::Vec3d;
using tomorig::calibration::PinholeCamera;

constexpr double kPi = 3.14159265358979323846;
constexpr double kFocalMm = 100.0, kPitchUm = 7.4, kDistanceMm = 263.16;
constexpr int kSize = 512;
const double kYaws[] = {-42.0, -14.0, 14.0, 42.0};

PinholeCamera thesis_camera(double yaw) { return PinholeCamera::yawed(yaw, kFocalMm, kPitchUm, kDistanceMm, kSize, kSize); }

// Eq. 3.12 rotation, translation (0, 0, D), perspective division, scaling by f / pitch and the
// principal point at (W - 1) / 2: written out independently of the library.
Vec2d reference_projection(double yaw_deg, const Vec3d& X) {
  const double phi = yaw_deg * kPi / 180.0;
  const double xc = std::cos(phi) * X.x - std::sin(phi) * X.z;
  const double yc = X.y;
  const double zc = std::sin(phi) * X.x + std::cos(phi) * X.z + kDistanceMm;
  const double f_px = kFocalMm / (kPitchUm / 1000.0);
  const double c = (kSize - 1) / 2.0;
  return {f_px * xc / zc + c, f_px * yc / zc + c};
}

Vec3d random_point(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> xy(-5.0, 5.0), z(-1.5, 1.5);
  return {xy(rng), xy(rng), z(rng)};
}

TEST(PinholeCamera, ProjectionMatchesIndependentFormulaForAllThesisYaws) {
  std::mt19937_64 rng(42);
  for (double yaw : kYaws) {
    const PinholeCamera cam = thesis_camera(yaw);
    for (int n = 0; n < 2000; ++n) {
      const Vec3d X = random_point(rng);
      const Vec2d expected = reference_projection(yaw, X);
      const Vec2d got = cam.project(X);
      ASSERT_NEAR(got.x, expected.x, 1e-6) << "yaw " << yaw;
      ASSERT_NEAR(got.y, expected.y, 1e-6) << "yaw " << yaw;
    }
  }
}

TEST(PinholeCamera, ParametersOfTheThesisCamera) {
  const auto p = thesis_camera(14).parameters();
  EXPECT_NEAR(p.fx, 13513.5135, 1e-3);
  EXPECT_NEAR(p.fy, 13513.5135, 1e-3);
  EXPECT_DOUBLE_EQ(p.cx, 255.5);
  EXPECT_DOUBLE_EQ(p.cy, 255.5);
  EXPECT_DOUBLE_EQ(p.t.z, kDistanceMm);
  const auto K = thesis_camera(14).intrinsics();
  EXPECT_DOUBLE_EQ(K[0], p.fx);
  EXPECT_DOUBLE_EQ(K[2], p.cx);
  EXPECT_DOUBLE_EQ(K[5], p.cy);
  EXPECT_DOUBLE_EQ(K[8], 1.0);
}

TEST(PinholeCamera, OriginImagesToTheImageCentre) {
  for (double yaw : kYaws) {
    const Vec2d c = thesis_camera(yaw).project({0, 0, 0});
    EXPECT_NEAR(c.x, 255.5, 1e-12);
    EXPECT_NEAR(c.y, 255.5, 1e-12);
  }
}

TEST(PinholeCamera, WorldXGrowsToTheRightAndYDownwardsAtYawZero) {
  const PinholeCamera cam = thesis_camera(0);
  EXPECT_GT(cam.project({1, 0, 0}).x, cam.project({0, 0, 0}).x);
  EXPECT_NEAR(cam.project({1, 0, 0}).y, 255.5, 1e-12);
  EXPECT_GT(cam.project({0, 1, 0}).y, cam.project({0, 0, 0}).y);
}

TEST(PinholeCamera, CentreIsAtTheDistanceAlongTheViewingDirection) {
  for (double yaw : kYaws) {
    const double phi = yaw * kPi / 180.0;
    const Vec3d c = thesis_camera(yaw).centre();
    EXPECT_NEAR(c.norm(), kDistanceMm, 1e-9);
    // The camera looks along R^T z_c = (sin phi, 0, cos phi); it sits D behind the origin.
    EXPECT_NEAR(c.x, -kDistanceMm * std::sin(phi), 1e-9);
    EXPECT_NEAR(c.y, 0.0, 1e-12);
    EXPECT_NEAR(c.z, -kDistanceMm * std::cos(phi), 1e-9);
  }
}

TEST(PinholeCamera, BackProjectionInvertsProjection) {
  std::mt19937_64 rng(7);
  for (double yaw : kYaws) {
    const PinholeCamera cam = thesis_camera(yaw);
    for (int n = 0; n < 2000; ++n) {
      const Vec3d X = random_point(rng);
      const Vec3d back = cam.back_project(cam.project(X), X.z);
      ASSERT_NEAR(back.x, X.x, 1e-9);
      ASSERT_NEAR(back.y, X.y, 1e-9);
      ASSERT_NEAR(back.z, X.z, 1e-9);
    }
  }
}

TEST(PinholeCamera, LineOfSightPassesThroughThePoint) {
  std::mt19937_64 rng(11);
  for (double yaw : kYaws) {
    const PinholeCamera cam = thesis_camera(yaw);
    for (int n = 0; n < 500; ++n) {
      const Vec3d X = random_point(rng);
      const tomorig::Ray ray = cam.line_of_sight(cam.project(X));
      ASSERT_NEAR(ray.direction.norm(), 1.0, 1e-12);
      const Vec3d cc = cam.centre();
      ASSERT_NEAR(ray.origin.x, cc.x, 1e-12);
      // Distance from X to the line: |(X - o) - ((X - o).d) d|.
      const Vec3d w = X - ray.origin;
      const double s = w.dot(ray.direction);
      ASSERT_GT(s, 0.0);  // in front of the camera
      ASSERT_NEAR((w - ray.direction * s).norm(), 0.0, 1e-9);
    }
  }
}

TEST(PinholeCamera, MagnificationAtTheOriginIsThesisValue) {
  for (double yaw : kYaws) {
    const PinholeCamera cam = thesis_camera(yaw);
    EXPECT_NEAR(cam.magnification({0, 0, 0}, kPitchUm), 0.38, 1e-4);
    // Object-space size of one pixel at the origin, from a finite difference of project().
    const double h = 0.1;  // mm along y (unaffected by the yaw)
    const double px_per_mm = (cam.project({0, h, 0}).y - cam.project({0, -h, 0}).y) / (2 * h);
    EXPECT_NEAR(1000.0 / px_per_mm, 19.47, 0.01);  // um per px ~ one 19.5 um voxel
  }
}

TEST(PinholeCamera, CloneProjectsTheSame) {
  const PinholeCamera cam = thesis_camera(-42);
  const auto copy = cam.clone();
  EXPECT_EQ(copy->model_name(), "pinhole");
  const Vec2d a = cam.project({1, 2, 0.5}), b = copy->project({1, 2, 0.5});
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
}

TEST(PinholeCamera, RejectsBadParameters) {
  EXPECT_THROW(PinholeCamera::yawed(0, 0, kPitchUm, kDistanceMm, kSize, kSize), tomorig::Error);
  EXPECT_THROW(PinholeCamera::yawed(0, kFocalMm, -1, kDistanceMm, kSize, kSize), tomorig::Error);
  EXPECT_THROW(PinholeCamera::yawed(0, kFocalMm, kPitchUm, 0, kSize, kSize), tomorig::Error);
  EXPECT_THROW(PinholeCamera::yawed(0, kFocalMm, kPitchUm, kDistanceMm, 0, kSize), tomorig::Error);
  tomorig::calibration::PinholeParameters p;
  p.fx = p.fy = 1000;
  p.R = {1, 0, 0, 0, 1, 0, 0, 0, -1};  // a reflection
  try {
    PinholeCamera bad(p);
    FAIL() << "a reflection was accepted as R";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
  }
}

}  // namespace
