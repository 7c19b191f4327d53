// The refractive model (issue 18, item 1): a camera in air behind 10 mm of glass into water
// (indices 1.0 / 1.49 / 1.33). Its projection agrees with the simulator's independently
// solved truth (sim::WindowView), its inverse with its projection, the calibration file
// keeps it, and fitted to a dot target on 7 planes it reproduces the true camera at held-out
// points to <= 0.05 px and <= 2 um, where a pinhole and rational2 cannot.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <random>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/refractive_camera.h"
#include "tomorig/simulators/window_view.h"

namespace {

using namespace tomorig;
using namespace tomorig::calibration;

constexpr int kSize = 2048;

// The true window: its medium face at z = -20 mm, tilted 0.5 degrees about y.
FlatWindow true_window() {
  FlatWindow w;
  const double tilt = 0.5 * std::numbers::pi / 180;
  w.normal = {std::sin(tilt), 0, std::cos(tilt)};
  w.medium_face_mm = -20;
  w.thickness_mm = 10;
  w.n_air = 1.0, w.n_window = 1.49, w.n_medium = 1.33;
  return w;
}

sim::WindowView true_view(double yaw_deg) {
  return {PinholeCamera::yawed(yaw_deg, 100.0, 7.4, 300.0, kSize, kSize), true_window()};
}

std::vector<PointCorrespondence> seven_planes(const sim::WindowView& view, double noise_px) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<PointCorrespondence> out;
  for (int k = 0; k < 7; ++k)
    for (int i = 0; i < 13; ++i)
      for (int j = 0; j < 13; ++j) {
        const Vec3d w{-15.0 + 30.0 * i / 12, -15.0 + 30.0 * j / 12, -6.0 + 2.0 * k};
        const Vec2d u = view.project(w);
        out.push_back({w, {u.x + noise(rng), u.y + noise(rng)}});
      }
  return out;
}

std::vector<Vec3d> held_out_points() {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> xy(-14.5, 14.5), z(-6.0, 6.0);
  std::vector<Vec3d> out;
  for (int k = 0; k < 300; ++k) out.push_back({xy(rng), xy(rng), z(rng)});
  return out;
}

struct Errors {
  double rms_px = 0, max_px = 0, rms_um = 0;
};
Errors against_truth(const CameraModel& model, const sim::WindowView& view) {
  Errors e;
  const auto points = held_out_points();
  for (const Vec3d& w : points) {
    const Vec2d a = model.project(w), b = view.project(w);
    const double px = std::hypot(a.x - b.x, a.y - b.y);
    const double um = 1000 * (model.back_project(b, w.z) - w).norm();
    e.rms_px += px * px;
    e.rms_um += um * um;
    e.max_px = std::max(e.max_px, px);
  }
  e.rms_px = std::sqrt(e.rms_px / points.size());
  e.rms_um = std::sqrt(e.rms_um / points.size());
  return e;
}

TEST(RefractiveCamera, ProjectionMatchesTheIndependentTruthAndInvertsExactly) {
  const sim::WindowView view = true_view(25);
  const RefractiveCamera model(LensCamera(view.camera.parameters(), {}), view.window);
  for (const Vec3d& w : held_out_points()) {
    const Vec2d a = model.project(w), b = view.project(w);
    ASSERT_LT(std::hypot(a.x - b.x, a.y - b.y), 1e-7) << w.x << " " << w.y << " " << w.z;
    EXPECT_LT((model.back_project(a, w.z) - w).norm(), 1e-9);
    const Ray ray = model.line_of_sight(a);
    const Vec3d further = ray.origin + ray.direction * ((w - ray.origin).dot(ray.direction) + 3.0);
    const Vec2d again = model.project(further);
    EXPECT_LT(std::hypot(again.x - a.x, again.y - a.y), 1e-7);
  }
  // The window matters: without it the same camera is off by pixels.
  const Vec2d plain = view.camera.project({10, 10, 6}), refracted = view.project({10, 10, 6});
  EXPECT_GT(std::hypot(plain.x - refracted.x, plain.y - refracted.y), 20.0);
}

TEST(RefractiveCamera, FitBehindGlassIntoWaterReachesTheTruthAtHeldOutPoints) {
  const sim::WindowView view = true_view(25);
  const auto points = seven_planes(view, 0.02);
  FitOptions options;
  FlatWindow start = true_window();  // the user's approximate pose: untilted, 1 mm off
  start.normal = {0, 0, 1};
  start.medium_face_mm = -21;
  options.window = start;
  FitReport report;
  const auto model = fit_camera_model("refractive", points, {kSize, kSize}, options, report);
  EXPECT_TRUE(report.converged);
  const Errors refractive = against_truth(*model, view);
  std::printf("%s\nagainst truth at held-out points: RMS %.4f px (max %.4f), %.3f um\n", report.brief().c_str(),
              refractive.rms_px, refractive.max_px, refractive.rms_um);
  EXPECT_LT(refractive.max_px, 0.05);
  EXPECT_LT(refractive.rms_um, 2.0);

  // The models without the window on the same points (figures for docs/accuracy.md).
  for (const std::string name : {"pinhole", "pinhole_distortion", "rational2", "soloff3"}) {
    FitReport other;
    const auto fitted = fit_camera_model(name, points, {kSize, kSize}, FitOptions{}, other);
    const Errors e = against_truth(*fitted, view);
    std::printf("%s: fit RMS %.4f px; against truth at held-out points: RMS %.4f px (max %.4f), %.3f um\n",
                name.c_str(), other.forward_rms_px, e.rms_px, e.max_px, e.rms_um);
    if (name == "pinhole") EXPECT_GT(e.max_px, 0.2);
  }

  // The calibration file keeps it exactly.
  const auto path = std::filesystem::temp_directory_path() / "tomorig_refractive_camera_test.toml";
  save_calibration(path, {{0, {kSize, kSize}, model->clone(), report}});
  const auto loaded = load_calibration(path);
  std::filesystem::remove(path);
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].model->model_name(), "refractive");
  const Vec3d w{3, -4, 1};
  EXPECT_EQ(loaded[0].model->project(w).x, model->project(w).x);
  EXPECT_EQ(loaded[0].model->project(w).y, model->project(w).y);
}

TEST(RefractiveCamera, AFitWithoutAWindowOrWithTheCameraInTheWaterIsRefused) {
  const sim::WindowView view = true_view(0);
  const auto points = seven_planes(view, 0.0);
  FitReport report;
  try {
    fit_camera_model("refractive", points, {kSize, kSize}, FitOptions{}, report);
    ADD_FAILURE() << "no window, yet accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("needs the window"), std::string::npos) << e.what();
  }
  FitOptions options;
  options.window = true_window();
  options.window->normal = {0, 0, -1};  // pointing back at the camera
  try {
    fit_camera_model("refractive", points, {kSize, kSize}, options, report);
    ADD_FAILURE() << "a window behind the camera was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("not on the air side of the window"), std::string::npos) << e.what();
  }
}

}  // namespace
