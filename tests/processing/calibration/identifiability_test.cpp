// Models refuse what the points cannot determine (issue 18, item 2): points on three lines
// fit rational2 and soloff3 to fractions of a pixel while the mapping between the lines is
// arbitrary; they must be refused naming the undetermined terms, while pinhole and DLT, which
// such points do determine, stay accurate against the true camera.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "../../../processing/src/calibration/identifiability.h"
#include "synthetic_points.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace {

using namespace calib_test;
using tomorig::Error;
using tomorig::calibration::FitOptions;
using tomorig::calibration::FitReport;
using tomorig::calibration::fit_camera_model;

// 45 points on three lines parallel to x, at three (y, z), seen by a pinhole with 0.3 px noise.
std::vector<PointCorrespondence> three_lines(const Truth& truth, double noise_px, unsigned seed = 5) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px);
  const double yz[3][2] = {{-3.0, -2.0}, {0.5, 0.0}, {3.5, 2.0}};
  std::vector<PointCorrespondence> out;
  for (const auto& line : yz)
    for (int i = 0; i < 15; ++i) {
      const Vec3d w{-4.0 + 8.0 * i / 14, line[0], line[1]};
      const Vec2d u = truth.image_of(w);
      out.push_back({w, {u.x + noise(rng), u.y + noise(rng)}});
    }
  return out;
}

std::string refusal(const std::string& model, const std::vector<PointCorrespondence>& points) {
  FitOptions options;
  options.camera = "camera 0";
  FitReport report;
  try {
    fit_camera_model(model, points, {kImageSize, kImageSize}, options, report);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input) << e.what();
    return e.what();
  }
  return {};
}

TEST(Identifiability, PointsOnThreeLinesRefuseRational2AndSoloff3NamingTheTerms) {
  const Truth truth;
  const auto points = three_lines(truth, 0.3);
  for (const std::string model : {"rational2", "soloff3"}) {
    const std::string message = refusal(model, points);
    ASSERT_FALSE(message.empty()) << model << " was accepted on points on three lines";
    EXPECT_NE(message.find("the 45 points lie on 3 lines parallel to x"), std::string::npos) << message;
    EXPECT_NE(message.find("y²"), std::string::npos) << message;
    EXPECT_NE(message.find("not determined"), std::string::npos) << message;
    if (model == "rational2") {
      EXPECT_NE(message.find("camera 0: the points do not determine the rational2 model"), std::string::npos) << message;
      EXPECT_NE(message.find("on these points y² is a combination of"), std::string::npos) << message;
      EXPECT_NE(message.find("use pinhole or dlt or pinhole_distortion"), std::string::npos) << message;
    } else {  // three lines parallel to x have three z values: soloff3's z³ needs four
      EXPECT_NE(message.find("the soloff3 model needs at least 4 planes"), std::string::npos) << message;
    }
  }
}

TEST(Identifiability, PinholeAndDltOnThreeLinesAreAcceptedAndAccurate) {
  const Truth truth;
  const auto points = three_lines(truth, 0.3);
  for (const std::string model : {"pinhole", "dlt"}) {
    FitOptions options;
    FitReport report;
    const auto fitted = fit_camera_model(model, points, {kImageSize, kImageSize}, options, report);
    EXPECT_TRUE(report.converged) << model;
    // The residual is the noise (0.3 px per axis: 0.42 px RMS length, less the fitted share).
    EXPECT_GT(report.forward_rms_px, 0.2) << model;
    EXPECT_LT(report.forward_rms_px, 0.5) << model;
    // The fitted camera is near the truth within the span of the lines.
    double worst = 0;
    for (const auto& p : three_lines(truth, 0.0)) {
      const Vec2d a = fitted->project(p.world);
      worst = std::max(worst, std::hypot(a.x - p.pixel.x, a.y - p.pixel.y));
    }
    EXPECT_LT(worst, 0.5) << model;
  }
}

TEST(Identifiability, AGridOnEnoughPlanesIsDeterminedForEveryModel) {
  const Truth truth;
  const auto points = grid_points(truth, kFivePlanes, 7, 4.0, 0.05);
  for (const std::string& model : tomorig::calibration::camera_model_names()) EXPECT_EQ(refusal(model, points), "") << model;
}

TEST(Identifiability, TwoplaneRefusesAPlaneWhosePointsLieOnTwoLines) {
  const Truth truth;
  auto points = grid_points(truth, {-1.0, 1.0}, 6);
  // Plane z = 1: keep only its rows y = -4 and y = 4 (12 points on two lines).
  std::vector<PointCorrespondence> kept;
  for (const auto& p : points)
    if (p.world.z < 0 || std::abs(std::abs(p.world.y) - 4.0) < 1e-9) kept.push_back(p);
  const std::string message = refusal("twoplane", kept);
  EXPECT_NE(message.find("plane z = 1 mm"), std::string::npos) << message;
  EXPECT_NE(message.find("lie on 2 lines parallel to x"), std::string::npos) << message;
  EXPECT_NE(message.find("y²"), std::string::npos) << message;
}

TEST(Identifiability, ARationalDenominatorThatChangesSignInTheBoxIsRefused) {
  using namespace tomorig::calibration;
  using namespace tomorig::calibration::detail;
  const MapForm form{Basis::quadratic, true};
  std::vector<double> c(30, 0.0);
  c[3] = 1;       // first numerator: p
  c[10 + 6] = 1;  // second numerator: q
  c[29] = 1;      // denominator 1 ...
  MapSamples inputs;
  inputs.inputs = {{-1, -1, -1}, {1, 1, 1}};
  inputs.targets = {{-1, -1}, {1, 1}};
  Normalization n;
  FitOptions options;
  options.camera = "camera 2";
  EXPECT_NO_THROW(require_one_signed_denominator(form, c, inputs, "rational2", "projection", n, true, {}, options));
  c[20 + 3] = 0.2;  // ... + 0.2 p: one sign over p in [-1, 1]
  EXPECT_NO_THROW(require_one_signed_denominator(form, c, inputs, "rational2", "projection", n, true, {}, options));
  // A zero shared with both numerators is a common factor, not a pole: (p (1 + 2p), q (1 + 2p)) / (1 + 2p).
  c[20 + 3] = 2.0;
  c[0] = 2, c[10 + 1] = 2;
  EXPECT_NO_THROW(require_one_signed_denominator(form, c, inputs, "rational2", "projection", n, true, {}, options));
  c[0] = 0, c[10 + 1] = 0;  // (p, q) / (1 + 2p): a pole at p = -0.5, inside the box
  try {
    require_one_signed_denominator(form, c, inputs, "rational2", "projection", n, true, {}, options);
    ADD_FAILURE() << "a pole inside the box was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("camera 2: the fitted rational2 projection has a pole inside the calibrated box"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("world (-"), std::string::npos) << message;  // on the p < -0.5 side
  }
}

}  // namespace
