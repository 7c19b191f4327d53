// Every way a camera-model fit can be handed unusable data ends in a tomorig::Error whose
// message names the camera (and the plane where one is at fault), never in a crash or a
// silently wrong model.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "synthetic_points.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace {

using namespace calib_test;
using tomorig::ErrorKind;
using tomorig::calibration::fit_camera_model;
using tomorig::calibration::FitOptions;
using tomorig::calibration::FitReport;

// Runs the fit, expecting an Error of `kind` whose message contains every one of `parts`.
void expect_error(const std::string& model, const std::vector<PointCorrespondence>& points, ErrorKind kind,
                  std::initializer_list<std::string> parts, FitOptions options = {}) {
  if (options.camera == "camera") options.camera = "camera 3";
  FitReport report;
  try {
    fit_camera_model(model, points, {kImageSize, kImageSize}, options, report);
    FAIL() << model << ": no error was raised";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    for (const auto& part : parts) EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

std::vector<PointCorrespondence> good_points() { return grid_points(Truth{}, kFivePlanes, 7); }

TEST(CameraModelBadInput, TooFewPointsForEachModel) {
  const auto all = good_points();
  // 5 points are too few even for the DLT (11 unknowns); 12 too few for rational2 (29).
  expect_error("dlt", {all.begin(), all.begin() + 5}, ErrorKind::bad_input, {"camera 3", "too few points", "dlt"});
  auto spread = grid_points(Truth{}, kFivePlanes, 2);  // 4 corners x 5 planes = 20 points
  spread.resize(12);
  expect_error("rational2", spread, ErrorKind::bad_input, {"camera 3", "too few points", "rational2", "15"});
}

TEST(CameraModelBadInput, AllPointsOnOnePlaneForAModelThatNeedsDepth) {
  const auto flat = grid_points(Truth{}, {0.5}, 9);
  for (const std::string model : {"dlt", "pinhole", "rational2", "soloff3", "twoplane"})
    expect_error(model, flat, ErrorKind::bad_input, {"camera 3", "one plane", "z = 0.5 mm", "needs depth"});
}

TEST(CameraModelBadInput, TooFewPlanesForTheHigherOrderModels) {
  const auto two = grid_points(Truth{}, {-1.0, 1.0}, 9);
  expect_error("rational2", two, ErrorKind::bad_input, {"camera 3", "2 planes", "at least 3"});
  expect_error("soloff3", grid_points(Truth{}, {-1.0, 0.0, 1.0}, 9), ErrorKind::bad_input,
               {"camera 3", "3 planes", "at least 4"});
}

TEST(CameraModelBadInput, CollinearPointsAreDegenerate) {
  // Points along one straight line through the volume: no camera can be fitted to them.
  std::vector<PointCorrespondence> line;
  const Truth truth;
  for (int k = 0; k < 40; ++k) {
    const Vec3d w{-4.0 + 0.2 * k, 0.1 * k - 2.0, 0.05 * k - 1.0};
    line.push_back({w, truth.image_of(w)});
  }
  for (const std::string model : {"dlt", "rational2", "twoplane"})
    expect_error(model, line, ErrorKind::bad_input, {"camera 3", "degenerate geometry", "collinear"});
}

TEST(CameraModelBadInput, TwoPlaneNamesThePlaneWhosePointsAreCollinear) {
  auto points = grid_points(Truth{}, {-1.0, 1.0}, 9);
  const Truth truth;
  for (int k = 0; k < 12; ++k) {  // a third plane with a single row of points
    const Vec3d w{-4.0 + 0.7 * k, 1.5, 2.0};
    points.push_back({w, truth.image_of(w)});
  }
  expect_error("twoplane", points, ErrorKind::bad_input, {"camera 3, plane 2", "z = 2 mm", "collinear"});
}

TEST(CameraModelBadInput, AFitThatDoesNotConvergeIsAnError) {
  Truth truth;
  truth.radial_k = 2e-3;
  FitOptions options;
  options.max_iterations = 1;
  options.retry_factor = 1;  // no second attempt
  expect_error("rational2", grid_points(truth, kFivePlanes, 9, 4.0, 0.05), ErrorKind::runtime,
               {"camera 3", "rational2", "did not converge in 1 iterations"}, options);
  // Asked not to throw, the fit returns and says so in its report.
  options.require_convergence = false;
  FitReport report;
  fit_camera_model("rational2", grid_points(truth, kFivePlanes, 9, 4.0, 0.05), {kImageSize, kImageSize}, options,
                   report);
  EXPECT_FALSE(report.converged);
}

TEST(CameraModelBadInput, AFitThatRunsOutOfIterationsGetsASecondAttemptBeforeItFails) {
  Truth truth;
  truth.radial_k = 2e-3;
  const auto points = grid_points(truth, kFivePlanes, 9, 4.0, 0.05);
  FitOptions options;
  options.max_iterations = 2;
  options.retry_factor = 100;  // 200 iterations: plenty
  FitReport report;
  const auto model = fit_camera_model("rational2", points, {kImageSize, kImageSize}, options, report);
  EXPECT_TRUE(report.converged);
  EXPECT_EQ(report.retry, "converged on a second attempt with 200 iterations");
  EXPECT_NE(report.brief().find("second attempt"), std::string::npos) << report.brief();
  EXPECT_LT(report.forward_rms_px, 0.1);
  // The failure message says both attempts ran out.
  options.retry_factor = 2;
  options.max_iterations = 1;
  expect_error("rational2", points, ErrorKind::runtime, {"did not converge in 1 iterations, nor in 2 on a second attempt"},
               options);
}

TEST(CameraModelBadInput, NonFinitePointUnknownModelAndBadOptions) {
  auto points = good_points();
  points[17].pixel.x = std::numeric_limits<double>::quiet_NaN();
  expect_error("dlt", points, ErrorKind::bad_input, {"camera 3", "point 17", "non-finite"});
  expect_error("tsai", good_points(), ErrorKind::bad_input, {"camera 3", "unknown camera model 'tsai'", "rational2"});
  FitOptions options;
  options.max_iterations = 0;
  expect_error("dlt", good_points(), ErrorKind::bad_input, {"camera 3", "max_iterations = 0"}, options);
  FitReport report;
  EXPECT_THROW(fit_camera_model("dlt", good_points(), {0, 512}, FitOptions{}, report), tomorig::Error);
}

}  // namespace
