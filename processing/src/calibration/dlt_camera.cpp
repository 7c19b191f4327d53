#include "tomorig/processing/calibration/dlt_camera.h"

#include <cmath>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

Eigen::Matrix3d left_block(const Mat34d& a) {
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m(i, j) = a[4 * i + j];
  return m;
}

}  // namespace

DltCamera::DltCamera(const Mat34d& matrix, const Normalization& normalization)
    : a_(matrix), normalization_(normalization) {
  for (int k = 0; k < 12; ++k)
    if (!std::isfinite(a_[k])) throw bad_input(fmt::format("dlt camera: matrix coefficient {} is {}", k, a_[k]));
  // A DLT is defined up to scale: fix it by the third row of the 3 x 3 block (the viewing
  // direction), keeping the sign, which says on which side "in front" lies.
  const double row3 = std::sqrt(a_[8] * a_[8] + a_[9] * a_[9] + a_[10] * a_[10]);
  if (!(row3 > 0)) throw bad_input("dlt camera: the third row of the matrix is zero: not a camera");
  for (double& v : a_) v /= row3;
  const Eigen::Matrix3d m = left_block(a_);
  const Eigen::FullPivLU<Eigen::Matrix3d> lu(m);
  if (!lu.isInvertible()) throw bad_input("dlt camera: the left 3 x 3 block of the matrix is singular: not a camera");
  const Eigen::Matrix3d inv = lu.inverse();
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) m_inverse_[3 * i + j] = inv(i, j);
  const Eigen::Vector3d c = -inv * Eigen::Vector3d(a_[3], a_[7], a_[11]);
  centre_ = {c.x(), c.y(), c.z()};
}

Vec2d DltCamera::project(const Vec3d& X) const {
  const double w = a_[8] * X.x + a_[9] * X.y + a_[10] * X.z + a_[11];
  return {(a_[0] * X.x + a_[1] * X.y + a_[2] * X.z + a_[3]) / w, (a_[4] * X.x + a_[5] * X.y + a_[6] * X.z + a_[7]) / w};
}

Vec3d DltCamera::world_direction(const Vec2d& pixel) const {
  // M^-1 [u v 1]^T: the point C + s d has w = s, so s > 0 lies in front of the camera.
  const auto& n = m_inverse_;
  return {n[0] * pixel.x + n[1] * pixel.y + n[2], n[3] * pixel.x + n[4] * pixel.y + n[5],
          n[6] * pixel.x + n[7] * pixel.y + n[8]};
}

Vec3d DltCamera::back_project(const Vec2d& pixel, double world_z) const {
  const Vec3d d = world_direction(pixel);
  if (std::abs(d.z) < 1e-12 * d.norm())
    throw runtime_error(fmt::format("dlt camera: the line of sight through pixel ({}, {}) is parallel to the plane z = {} mm",
                                    pixel.x, pixel.y, world_z));
  Vec3d point = centre_ + d * ((world_z - centre_.z) / d.z);
  point.z = world_z;
  return point;
}

Ray DltCamera::line_of_sight(const Vec2d& pixel) const {
  const Vec3d d = world_direction(pixel);
  return {centre_, d * (1.0 / d.norm())};
}

std::optional<PinholeDecomposition> DltCamera::decompose() const {
  // RQ decomposition M = K R through a QR decomposition of the row-reversed, transposed M.
  const Eigen::Matrix3d m = left_block(a_);
  Eigen::Matrix3d flip = Eigen::Matrix3d::Zero();
  flip(0, 2) = flip(1, 1) = flip(2, 0) = 1;
  const Eigen::HouseholderQR<Eigen::Matrix3d> qr((flip * m).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K = flip * r.transpose() * flip;
  Eigen::Matrix3d R = flip * q.transpose();
  // Positive diagonal of K (the sign goes into R).
  for (int i = 0; i < 3; ++i)
    if (K(i, i) < 0) {
      K.col(i) *= -1;
      R.row(i) *= -1;
    }
  // A mirrored image (det R = -1) is not a pinhole camera in our pixel convention.
  if (R.determinant() < 0 || !(K(2, 2) > 0)) return std::nullopt;
  const double scale = K(2, 2);
  K /= scale;
  const Eigen::Vector3d t = K.inverse() * Eigen::Vector3d(a_[3], a_[7], a_[11]) / scale;
  PinholeDecomposition d;
  d.parameters.fx = K(0, 0);
  d.parameters.fy = K(1, 1);
  d.parameters.cx = K(0, 2);
  d.parameters.cy = K(1, 2);
  d.skew = K(0, 1);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d.parameters.R[3 * i + j] = R(i, j);
  d.parameters.t = {t.x(), t.y(), t.z()};
  return d;
}

std::unique_ptr<CameraModel> DltCamera::clone() const { return std::make_unique<DltCamera>(*this); }

}  // namespace tomorig::calibration
