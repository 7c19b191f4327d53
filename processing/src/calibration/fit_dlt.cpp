// DLT (thesis Appendix A.2.1) and the pinhole model refined from it.
#include <cmath>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <fmt/core.h>

#include "mapping_fit.h"
#include "model_fits.h"
#include "projection_fit.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/dlt_camera.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace tomorig::calibration::detail {
namespace {

constexpr int kDltUnknowns = 11;
constexpr int kPinholeUnknowns = 10;  // fx, fy, cx, cy, rotation vector, t

MapSamples forward_samples(std::span<const PointCorrespondence> points, const Normalization& n) {
  MapSamples s;
  for (const auto& p : points) {
    const Vec3d w = n.to_normalised(p.world);
    s.inputs.push_back({w.x, w.y, w.z});
    s.targets.push_back(n.to_normalised(p.pixel));
  }
  return s;
}

// The normalised DLT turned into a direct world (mm) -> pixel matrix: T_I^-1 A~ T_W.
Mat34d denormalise(const std::vector<double>& a, const Normalization& n) {
  Eigen::Matrix<double, 3, 4> A;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) A(i, j) = a[4 * i + j];
  Eigen::Matrix4d tw = Eigen::Matrix4d::Identity() / n.world_scale;
  tw(3, 3) = 1;
  tw.block<3, 1>(0, 3) = -Eigen::Vector3d(n.world_centre.x, n.world_centre.y, n.world_centre.z) / n.world_scale;
  Eigen::Matrix3d ti_inv = Eigen::Matrix3d::Identity() * n.image_scale;
  ti_inv(2, 2) = 1;
  ti_inv(0, 2) = n.image_centre.x;
  ti_inv(1, 2) = n.image_centre.y;
  const Eigen::Matrix<double, 3, 4> P = ti_inv * A * tw;
  Mat34d out;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) out[4 * i + j] = P(i, j);
  return out;
}

}  // namespace

DltEstimate estimate_dlt(std::span<const PointCorrespondence> points, const Normalization& n, const FitOptions& options) {
  const MapSamples samples = forward_samples(points, n);
  const int count = static_cast<int>(points.size());
  // Eq. A.2: L a = 0 with a = (a11 .. a34), the right singular vector of the smallest
  // singular value.
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(2 * count, 12);
  for (int i = 0; i < count; ++i) {
    const auto& x = samples.inputs[i];
    const Vec2d u = samples.targets[i];
    for (int j = 0; j < 3; ++j) {
      L(2 * i, j) = x[j];
      L(2 * i + 1, 4 + j) = x[j];
      L(2 * i, 8 + j) = -x[j] * u.x;
      L(2 * i + 1, 8 + j) = -x[j] * u.y;
    }
    L(2 * i, 3) = L(2 * i + 1, 7) = 1;
    L(2 * i, 11) = -u.x;
    L(2 * i + 1, 11) = -u.y;
  }
  // L P = Q R with R 12 x 12: R has the singular values of L, its right singular vectors
  // are those of L permuted, and its SVD costs nothing however many points there are. (The
  // unblocked column-pivoting QR: the blocked one calls Eigen's OpenMP-parallel product.)
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(L);
  const Eigen::MatrixXd R = qr.matrixR().topRows(12).triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  if (!(sv(10) > 1e-8 * sv(0)))
    throw bad_input(fmt::format("{}: degenerate geometry for the dlt model: the linear system (Eq. A.2) has more than "
                                "one solution (singular values {:.3g} and {:.3g} of {:.3g}); the points must not lie on "
                                "one plane or line",
                                options.camera, sv(10), sv(11), sv(0)));
  const Eigen::VectorXd v = qr.colsPermutation() * svd.matrixV().col(11);
  // a34 is the denominator at the centroid (the origin of the normalised frame): it is far
  // from 0 for any camera that sees the points, and dividing by it puts w > 0 in front.
  if (!(std::abs(v(11)) > 1e-9))
    throw bad_input(fmt::format("{}: degenerate geometry for the dlt model: the centroid of the points projects to "
                                "infinity",
                                options.camera));
  std::vector<double> initial(12);
  for (int k = 0; k < 12; ++k) initial[k] = v(k) / v(11);
  DltEstimate estimate;
  MapFit fit = fit_map({Basis::linear, true}, samples, initial, lm_settings(options));
  check_fit(fit.lm, kDltUnknowns, "dlt", "projection", options);
  estimate.normalised = std::move(fit.coefficients);
  estimate.lm = fit.lm;
  return estimate;
}

std::unique_ptr<CameraModel> fit_dlt(std::span<const PointCorrespondence> points, const FitOptions& options,
                                     FitReport& report) {
  const Normalization n = check_points(points, {"dlt", kDltUnknowns, 2, 0}, options);
  const DltEstimate dlt = estimate_dlt(points, n, options);
  report.normalization = n;
  report.iterations = dlt.lm.iterations;
  report.converged = dlt.lm.converged;
  return std::make_unique<DltCamera>(denormalise(dlt.normalised, n), n);
}

namespace {

// fx, fy, cx, cy, rotation vector (3), t (3): the parameters the pinhole-based fits vary.
std::array<double, 10> pinhole_vector(const PinholeParameters& s) {
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = s.R[3 * i + j];
  const Eigen::AngleAxisd aa(R);
  const Eigen::Vector3d rv = aa.angle() * aa.axis();
  return {s.fx, s.fy, s.cx, s.cy, rv.x(), rv.y(), rv.z(), s.t.x, s.t.y, s.t.z};
}

}  // namespace

PinholeParameters pinhole_of(const Eigen::VectorXd& q) {
  PinholeParameters pp;
  pp.fx = q(0), pp.fy = q(1), pp.cx = q(2), pp.cy = q(3);
  const Eigen::Vector3d r(q(4), q(5), q(6));
  const double angle = r.norm();
  const Eigen::Matrix3d rot = angle > 0 ? Eigen::AngleAxisd(angle, r / angle).toRotationMatrix() : Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pp.R[3 * i + j] = rot(i, j);
  pp.t = {q(7), q(8), q(9)};
  return pp;
}

PinholeStart pinhole_start(std::span<const PointCorrespondence> points, const FitOptions& options) {
  FitOptions start_options = options;
  start_options.require_convergence = false;  // the full fit goes on from it
  FitReport start_report;
  const auto start = fit_pinhole(points, start_options, start_report);
  return {pinhole_vector(static_cast<const PinholeCamera&>(*start).parameters()), start_report.normalization};
}

std::unique_ptr<CameraModel> fit_pinhole(std::span<const PointCorrespondence> points, const FitOptions& options,
                                         FitReport& report) {
  // Started from the DLT, so it needs the DLT's points (11 unknowns), not just its own 10.
  const Normalization n = check_points(points, {"pinhole", kDltUnknowns, 2, 0}, options);
  const DltEstimate dlt = estimate_dlt(points, n, options);
  const auto decomposition = DltCamera(denormalise(dlt.normalised, n)).decompose();
  if (!decomposition)
    throw bad_input(fmt::format("{}: the fitted DLT is not that of a pinhole camera (the image is mirrored); check the "
                                "orientation of the image or of the world axes",
                                options.camera));
  const PinholeParameters& start = decomposition->parameters;
  // Parameters: fx, fy, cx, cy, rotation vector (3), t (3).
  const std::array<double, 10> v = pinhole_vector(start);
  Eigen::VectorXd p = Eigen::Map<const Eigen::VectorXd>(v.data(), kPinholeUnknowns);

  const ProjectPoints project = [&](const Eigen::VectorXd& q, std::span<Vec2d> pixels) {
    const PinholeParameters pp = pinhole_of(q);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3d& X = points[i].world;
      const double xc = pp.R[0] * X.x + pp.R[1] * X.y + pp.R[2] * X.z + pp.t.x;
      const double yc = pp.R[3] * X.x + pp.R[4] * X.y + pp.R[5] * X.z + pp.t.y;
      const double zc = pp.R[6] * X.x + pp.R[7] * X.y + pp.R[8] * X.z + pp.t.z;
      pixels[i] = {pp.fx * xc / zc + pp.cx, pp.fy * yc / zc + pp.cy};
    }
  };
  const LmResult lm = fit_projection(points, n.image_scale, project, p, lm_settings(options));
  check_fit(lm, kPinholeUnknowns, "pinhole", "projection", options);
  report.normalization = n;
  report.iterations = lm.iterations;
  report.converged = lm.converged;
  return std::make_unique<PinholeCamera>(pinhole_of(p));
}

}  // namespace tomorig::calibration::detail
