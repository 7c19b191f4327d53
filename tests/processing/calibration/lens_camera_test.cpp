// The pinhole camera with lens distortion (issue 18, item 1): its inverse agrees with its
// projection, it survives the calibration file bit for bit, and fitted to a rig with strong
// barrel distortion it reproduces the true camera at points not used in the fit.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <vector>

#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/lens_camera.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace {

using namespace tomorig;
using namespace tomorig::calibration;

constexpr int kSize = 2048;

// The true camera: a pinhole, then barrel distortion about the image centre written
// independently of LensCamera: 2 % of the radius at the image corner (29 px there).
struct BarrelTruth {
  PinholeCamera pinhole = PinholeCamera::yawed(20, 100.0, 7.4, 300.0, kSize, kSize);
  double corner_fraction = -0.02;

  Vec2d image_of(const Vec3d& world) const {
    const Vec2d u = pinhole.project(world);
    const double c = (kSize - 1) / 2.0, corner = c * std::sqrt(2.0);
    const double dx = u.x - c, dy = u.y - c;
    const double f = 1 + corner_fraction * (dx * dx + dy * dy) / (corner * corner);
    return {c + dx * f, c + dy * f};
  }
};

std::vector<PointCorrespondence> grid(const BarrelTruth& truth, double noise_px) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<PointCorrespondence> out;
  for (double z : {-6.0, -3.0, 0.0, 3.0, 6.0})
    for (int i = 0; i < 15; ++i)
      for (int j = 0; j < 15; ++j) {
        const Vec3d w{-20.0 + 40.0 * i / 14, -20.0 + 40.0 * j / 14, z};
        const Vec2d u = truth.image_of(w);
        out.push_back({w, {u.x + noise(rng), u.y + noise(rng)}});
      }
  return out;
}

TEST(LensCamera, BackProjectionAndLineOfSightInvertTheProjection) {
  PinholeParameters p = PinholeCamera::yawed(-30, 100.0, 7.4, 300.0, kSize, kSize).parameters();
  const LensCamera camera(p, {-0.3, 0.1, -0.02, 1e-3, -2e-3});
  for (const Vec3d w : {Vec3d{0, 0, 0}, Vec3d{19, -18, 5}, Vec3d{-20, 20, -6}}) {
    const Vec2d u = camera.project(w);
    const Vec3d back = camera.back_project(u, w.z);
    EXPECT_LT((back - w).norm(), 1e-9);
    const Ray ray = camera.line_of_sight(u);
    const Vec3d along = ray.origin + ray.direction * ((w - ray.origin).dot(ray.direction) + 25.0);
    const Vec2d again = camera.project(along);
    EXPECT_LT(std::hypot(again.x - u.x, again.y - u.y), 1e-8);
  }
}

TEST(LensCamera, FitsStrongBarrelDistortionToFiveHundredthsOfAPixelAtHeldOutPoints) {
  const BarrelTruth truth;
  const auto points = grid(truth, 0.02);
  // The distortion really is tens of pixels at the corners of the image.
  const Vec2d corner_ideal = truth.pinhole.project({20, 20, 6});
  const Vec2d corner = truth.image_of({20, 20, 6});
  EXPECT_GT(std::hypot(corner.x - corner_ideal.x, corner.y - corner_ideal.y), 10.0);

  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> xy(-19.0, 19.0), z(-6.0, 6.0);
  std::vector<Vec3d> held_out;
  for (int k = 0; k < 300; ++k) held_out.push_back({xy(rng), xy(rng), z(rng)});
  auto worst_error = [&](const CameraModel& m) {
    double worst = 0;
    for (const Vec3d& w : held_out) {
      const Vec2d a = m.project(w), b = truth.image_of(w);
      worst = std::max(worst, std::hypot(a.x - b.x, a.y - b.y));
    }
    return worst;
  };
  FitReport report;
  const auto lens = fit_camera_model("pinhole_distortion", points, {kSize, kSize}, FitOptions{}, report);
  EXPECT_EQ(lens->model_name(), "pinhole_distortion");
  EXPECT_TRUE(report.converged);
  EXPECT_LT(worst_error(*lens), 0.05);
  EXPECT_LT(report.forward_rms_px, 0.04);  // the noise: 0.02 px per axis
  FitReport pinhole_report;
  const auto pinhole = fit_camera_model("pinhole", points, {kSize, kSize}, FitOptions{}, pinhole_report);
  EXPECT_GT(worst_error(*pinhole), 2.0);  // what the distortion costs a plain pinhole

  // The calibration file keeps it exactly.
  const auto path = std::filesystem::temp_directory_path() / "tomorig_lens_camera_test.toml";
  save_calibration(path, {{0, {kSize, kSize}, lens->clone(), report}});
  const auto loaded = load_calibration(path);
  std::filesystem::remove(path);
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].model->model_name(), "pinhole_distortion");
  for (const Vec3d& w : held_out) {
    const Vec2d a = loaded[0].model->project(w), b = lens->project(w);
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
  }
}

}  // namespace
