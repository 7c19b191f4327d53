// The calibration file: a save -> load round trip reproduces every model's projections bit
// for bit, and a damaged file is refused with an error naming the camera and the key.
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "synthetic_points.h"
#include "temp_dir.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace {

using namespace calib_test;
using tomorig::ErrorKind;
using tomorig::calibration::CameraCalibration;
using tomorig::calibration::fit_camera_model;
using tomorig::calibration::FitOptions;
using tomorig::calibration::load_calibration;
using tomorig::calibration::save_calibration;

// One camera per model, ids 0..5, fitted to distorted points once for the whole suite.
std::vector<CameraCalibration> fit_cameras() {
  Truth truth;
  truth.camera = thesis_camera(-14);
  truth.radial_k = 7e-4;
  const auto points = grid_points(truth, kFivePlanes, 9, 4.0, 0.02);
  std::vector<CameraCalibration> cameras;
  int id = 0;
  for (const auto& name : tomorig::calibration::camera_model_names()) {
    CameraCalibration c;
    c.id = id++;
    c.image_size = {kImageSize, kImageSize};
    FitOptions options;
    options.camera = "camera " + std::to_string(c.id);
    c.model = fit_camera_model(name, points, c.image_size, options, c.report);
    cameras.push_back(std::move(c));
  }
  return cameras;
}

const std::vector<CameraCalibration>& fitted_cameras() {
  static const std::vector<CameraCalibration> cameras = fit_cameras();
  return cameras;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expect_bad_input(const std::filesystem::path& file, std::initializer_list<std::string> parts) {
  try {
    load_calibration(file);
    FAIL() << "the file was accepted";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input) << e.what();
    for (const auto& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(CalibrationFile, SaveLoadRoundTripReproducesProjectionsExactly) {
  tomorig::testing::TempDir dir;
  const auto cameras = fitted_cameras();
  save_calibration(dir / "calib.toml", cameras);
  const auto loaded = load_calibration(dir / "calib.toml");
  ASSERT_EQ(loaded.size(), cameras.size());
  const auto probes = random_points(50, 3.8, -1.9, 1.9, 17);
  for (std::size_t k = 0; k < cameras.size(); ++k) {
    const auto& a = cameras[k];
    const auto& b = loaded[k];
    EXPECT_EQ(b.id, a.id);
    EXPECT_EQ(b.model->model_name(), a.model->model_name());
    EXPECT_EQ(b.image_size.width, kImageSize);
    EXPECT_EQ(b.report.points, a.report.points);
    EXPECT_EQ(b.report.forward_mean_px, a.report.forward_mean_px);
    EXPECT_EQ(b.report.reverse_mean_um, a.report.reverse_mean_um);
    EXPECT_EQ(b.report.converged, a.report.converged);
    EXPECT_EQ(b.report.inverse_mapping_mean_um.has_value(), a.report.inverse_mapping_mean_um.has_value());
    EXPECT_EQ(b.report.normalization.world_scale, a.report.normalization.world_scale);
    for (const Vec3d& X : probes) {
      const Vec2d u = a.model->project(X), v = b.model->project(X);
      ASSERT_EQ(u.x, v.x) << a.model->model_name();
      ASSERT_EQ(u.y, v.y) << a.model->model_name();
      const Vec3d p = a.model->back_project(u, X.z), q = b.model->back_project(u, X.z);
      ASSERT_EQ(p.x, q.x) << a.model->model_name();
      ASSERT_EQ(p.y, q.y) << a.model->model_name();
    }
  }
}

TEST(CalibrationFile, ANanCoefficientIsRefusedNamingCameraAndKey) {
  tomorig::testing::TempDir dir;
  save_calibration(dir / "calib.toml", fitted_cameras());
  std::string text = read_text(dir / "calib.toml");
  // Camera 4 is rational2 (the order of camera_model_names()): spoil its 8th forward value.
  const std::string key = "forward = [";
  std::size_t at = 0;
  for (int seen = 0; seen < 1; ++seen) at = text.find(key, at) + key.size();  // first "forward" list
  ASSERT_NE(text.find(key), std::string::npos);
  std::size_t value = at;
  for (int k = 0; k < 7; ++k) value = text.find(", ", value) + 2;
  const std::size_t end = text.find(',', value);
  text.replace(value, end - value, "nan");
  expect_bad_input(dir.write("nan.toml", text), {"camera 4", "coefficients.forward[7]", "nan"});
}

TEST(CalibrationFile, MissingOrMistypedValuesAreRefused) {
  tomorig::testing::TempDir dir;
  save_calibration(dir / "calib.toml", fitted_cameras());
  const std::string text = read_text(dir / "calib.toml");
  // Camera 0 is the pinhole: drop its fy.
  expect_bad_input(dir.write("no_fy.toml", std::regex_replace(text, std::regex("\nfy = [^\n]*"), "")),
                   {"camera 0", "coefficients.fy", "missing"});
  expect_bad_input(dir.write("bad_scale.toml", std::regex_replace(text, std::regex("\nworld_scale = [^\n]*"),
                                                                  "\nworld_scale = \"big\"", std::regex_constants::format_first_only)),
                   {"camera 0", "normalization.world_scale", "number"});
  expect_bad_input(dir.write("inf.toml", std::regex_replace(text, std::regex("\nreverse_mean_um = [^\n]*"),
                                                            "\nreverse_mean_um = inf")),
                   {"camera 0", "fit.reverse_mean_um"});
  expect_bad_input(dir.write("syntax.toml", "format = \"tomorig-calibration\"\nversion = 1\n[[camera]\n"), {"line"});
  expect_bad_input(dir.write("other.toml", "name = \"rig\"\n"), {"not a tomorig calibration file"});
  expect_bad_input(dir / "absent.toml", {"does not exist"});
}

TEST(CalibrationFile, AModelWithoutARotationIsRefusedNamingTheCamera) {
  tomorig::testing::TempDir dir;
  save_calibration(dir / "calib.toml", fitted_cameras());
  const std::string text = read_text(dir / "calib.toml");
  const std::string spoiled = std::regex_replace(text, std::regex("\nR = \\[[^,]*,"), "\nR = [2.0,");
  expect_bad_input(dir.write("r.toml", spoiled), {"camera 0", "coefficients", "rotation"});
}

}  // namespace
