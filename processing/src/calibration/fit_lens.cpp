// The pinhole camera with lens distortion (lens_camera.h): started from the fitted pinhole with
// no distortion, then Levenberg-Marquardt on the reprojection error (Eq. A.3) over the pinhole's
// 10 parameters and k1, k2, k3, p1, p2.
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <fmt/core.h>

#include "model_fits.h"
#include "projection_fit.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/lens_camera.h"

namespace tomorig::calibration::detail {
namespace {

constexpr int kPinholeParameters = 10;  // fx, fy, cx, cy, rotation vector, t
constexpr int kLensParameters = kPinholeParameters + 5;

LensDistortion distortion_of(const Eigen::VectorXd& q) {
  return {q(10), q(11), q(12), q(13), q(14)};
}

}  // namespace

std::unique_ptr<CameraModel> fit_lens(std::span<const PointCorrespondence> points, const FitOptions& options,
                                      FitReport& report) {
  check_points(points, {"pinhole_distortion", kLensParameters, 2, 0}, options);
  // The start: the pinhole fit; the full fit goes on from it.
  const PinholeStart start = pinhole_start(points, options);
  const Normalization& n = start.normalization;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(kLensParameters);
  for (int i = 0; i < kPinholeParameters; ++i) p(i) = start.parameters[static_cast<std::size_t>(i)];

  const ProjectPoints project = [&](const Eigen::VectorXd& q, std::span<Vec2d> pixels) {
    const PinholeParameters pp = pinhole_of(q);
    const LensDistortion d = distortion_of(q);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3d& X = points[i].world;
      const double xc = pp.R[0] * X.x + pp.R[1] * X.y + pp.R[2] * X.z + pp.t.x;
      const double yc = pp.R[3] * X.x + pp.R[4] * X.y + pp.R[5] * X.z + pp.t.y;
      const double zc = pp.R[6] * X.x + pp.R[7] * X.y + pp.R[8] * X.z + pp.t.z;
      const Vec2d u = d.distort({xc / zc, yc / zc});
      pixels[i] = {pp.fx * u.x + pp.cx, pp.fy * u.y + pp.cy};
    }
  };
  const LmResult lm = fit_projection(points, n.image_scale, project, p, lm_settings(options));
  check_fit(lm, kLensParameters, "pinhole_distortion", "projection", options);
  report.normalization = n;
  report.iterations = lm.iterations;
  report.converged = lm.converged;
  return std::make_unique<LensCamera>(pinhole_of(p), distortion_of(p));
}

}  // namespace tomorig::calibration::detail
