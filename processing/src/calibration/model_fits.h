#pragma once
// The per-model fits behind fit_camera_model(), and the input checks they share.
#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "levenberg_marquardt.h"
#include "polynomial_maps.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/calibration/polynomial_camera.h"

namespace tomorig::calibration::detail {

// Points grouped by world z (within 1e-6 mm), sorted by z.
struct Plane {
  double z = 0;
  std::vector<PointCorrespondence> points;
};
std::vector<Plane> group_by_plane(std::span<const PointCorrespondence> points);

// What a model needs from its data: checked before fitting, each failure a bad_input naming
// the camera (and the plane).
struct Requirements {
  std::string model;
  int unknowns = 0;    // coefficients fitted from the forward residuals (2 per point)
  int min_planes = 2;  // distinct z values
  int min_points_per_plane = 0;
  // The monomials of the model's mapping: every one must be determined by the points (else the
  // mapping between them is arbitrary: points on three lines lie on a quadric, and a quadratic
  // numerator can change by it freely). nullopt: no such check.
  std::optional<Basis> basis;
};

// Checks the points and returns their normalisation (Appendix A.1).
Normalization check_points(std::span<const PointCorrespondence> points, const Requirements& req, const FitOptions& options);

// After an LM fit: throws bad_input if the data do not determine the parameters (degenerate
// geometry; only when `identifiable`: a ratio of polynomials is not, since numerator and
// denominator may share a factor), runtime if it did not converge and the options require it.
void check_fit(const LmResult& lm, int parameters, const std::string& model, const std::string& what,
               const FitOptions& options, bool identifiable = true);

LmSettings lm_settings(const FitOptions& options);

struct DltEstimate {
  std::vector<double> normalised;  // a11..a34 in normalised coordinates, a34 = 1
  LmResult lm;
};
// SVD of Eq. A.2 on normalised points, then LM on Eq. A.3 (11 parameters, a34 = 1).
DltEstimate estimate_dlt(std::span<const PointCorrespondence> points, const Normalization& n, const FitOptions& options);

std::unique_ptr<CameraModel> fit_dlt(std::span<const PointCorrespondence> points, const FitOptions& options,
                                     FitReport& report);
std::unique_ptr<CameraModel> fit_pinhole(std::span<const PointCorrespondence> points, const FitOptions& options,
                                         FitReport& report);
// The start of the models built on a pinhole (pinhole_distortion, refractive): a pinhole fit
// that need not converge itself, as fx, fy, cx, cy, rotation vector (3), t (3), and the
// points' normalisation.
struct PinholeStart {
  std::array<double, 10> parameters{};
  Normalization normalization;
};
PinholeStart pinhole_start(std::span<const PointCorrespondence> points, const FitOptions& options);
// The inverse of that vector's first 10 entries (the rotation vector back to a matrix).
PinholeParameters pinhole_of(const Eigen::VectorXd& q);

std::unique_ptr<CameraModel> fit_lens(std::span<const PointCorrespondence> points, const FitOptions& options,
                                      FitReport& report);
std::unique_ptr<CameraModel> fit_refractive(std::span<const PointCorrespondence> points, const FitOptions& options,
                                            FitReport& report);
std::unique_ptr<CameraModel> fit_polynomial(PolynomialKind kind, std::span<const PointCorrespondence> points,
                                            const FitOptions& options, FitReport& report);
std::unique_ptr<CameraModel> fit_two_plane(std::span<const PointCorrespondence> points, const FitOptions& options,
                                           FitReport& report);

}  // namespace tomorig::calibration::detail
