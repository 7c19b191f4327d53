#include "tomorig/processing/calibration/pinhole_camera.h"

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

// R * v for a row-major R.
Vec3d multiply(const Mat3d& R, const Vec3d& v) {
  return {R[0] * v.x + R[1] * v.y + R[2] * v.z, R[3] * v.x + R[4] * v.y + R[5] * v.z,
          R[6] * v.x + R[7] * v.y + R[8] * v.z};
}

// R^T * v: the inverse rotation, without forming the transpose.
Vec3d multiply_transposed(const Mat3d& R, const Vec3d& v) {
  return {R[0] * v.x + R[3] * v.y + R[6] * v.z, R[1] * v.x + R[4] * v.y + R[7] * v.z,
          R[2] * v.x + R[5] * v.y + R[8] * v.z};
}

// R^T R = I and det R = +1, to 1e-6: a reflection or a scaled matrix would silently mirror
// or stretch every projection, so it is refused up front.
bool is_rotation(const Mat3d& R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += R[3 * k + i] * R[3 * k + j];
      if (std::abs(dot - (i == j ? 1.0 : 0.0)) > 1e-6) return false;
    }
  const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                     R[2] * (R[3] * R[7] - R[4] * R[6]);
  return std::abs(det - 1.0) <= 1e-6;
}

void require_positive(double value, const char* name) {
  if (!(value > 0) || !std::isfinite(value))
    throw bad_input(fmt::format("pinhole camera: {} = {} is invalid: it must be > 0", name, value));
}

}  // namespace

PinholeCamera::PinholeCamera(const PinholeParameters& p) : p_(p) {
  require_positive(p.fx, "fx");
  require_positive(p.fy, "fy");
  if (!is_rotation(p.R))
    throw bad_input("pinhole camera: R is not a rotation matrix (R^T R must be I and det R = +1)");
  centre_ = multiply_transposed(p_.R, p_.t) * -1.0;
}

PinholeCamera PinholeCamera::yawed(double yaw_deg, double focal_length_mm, double pixel_pitch_um,
                                   double distance_mm, int width, int height) {
  require_positive(focal_length_mm, "focal_length_mm");
  require_positive(pixel_pitch_um, "pixel_pitch_um");
  require_positive(distance_mm, "distance_mm");
  if (width <= 0 || height <= 0)
    throw bad_input(fmt::format("pinhole camera: image size {} x {} is invalid: width and height must be > 0",
                                width, height));
  if (!std::isfinite(yaw_deg)) throw bad_input("pinhole camera: yaw_deg must be a finite number");

  const double phi = yaw_deg * std::numbers::pi / 180.0;
  const double c = std::cos(phi), s = std::sin(phi);
  PinholeParameters p;
  p.fx = p.fy = focal_length_mm / (pixel_pitch_um * 1e-3);
  // Pixel centres sit at integer coordinates, so the centre of a W-pixel row is (W - 1) / 2.
  p.cx = (width - 1) * 0.5;
  p.cy = (height - 1) * 0.5;
  p.R = {c, 0, -s, 0, 1, 0, s, 0, c};  // Eq. 3.12
  // The world origin maps to (0, 0, D) in camera coordinates: on the axis, D in front.
  p.t = {0, 0, distance_mm};
  return PinholeCamera(p);
}

Mat3d PinholeCamera::intrinsics() const { return {p_.fx, 0, p_.cx, 0, p_.fy, p_.cy, 0, 0, 1}; }

Vec3d PinholeCamera::centre() const { return centre_; }

Vec3d PinholeCamera::to_camera(const Vec3d& world) const { return multiply(p_.R, world) + p_.t; }

double PinholeCamera::magnification(const Vec3d& world, double pixel_pitch_um) const {
  // f [mm] = fx [px] * pitch [mm/px]; magnification = f / depth.
  return p_.fx * pixel_pitch_um * 1e-3 / to_camera(world).z;
}

Vec2d PinholeCamera::project(const Vec3d& world) const {
  const Vec3d c = to_camera(world);
  const double inv_z = 1.0 / c.z;
  return {p_.fx * c.x * inv_z + p_.cx, p_.fy * c.y * inv_z + p_.cy};
}

Vec3d PinholeCamera::world_direction(const Vec2d& pixel) const {
  // K^-1 [u v 1]^T in camera coordinates, rotated back to the world.
  const Vec3d camera_dir{(pixel.x - p_.cx) / p_.fx, (pixel.y - p_.cy) / p_.fy, 1.0};
  return multiply_transposed(p_.R, camera_dir);
}

Vec3d PinholeCamera::back_project(const Vec2d& pixel, double world_z) const {
  const Vec3d d = world_direction(pixel);
  if (std::abs(d.z) < 1e-12 * d.norm())
    throw runtime_error(fmt::format("pinhole camera: the line of sight through pixel ({}, {}) is parallel to "
                                    "the plane z = {} mm",
                                    pixel.x, pixel.y, world_z));
  const double s = (world_z - centre_.z) / d.z;
  Vec3d point = centre_ + d * s;
  point.z = world_z;  // exact, whatever the rounding in centre_ + d * s
  return point;
}

Ray PinholeCamera::line_of_sight(const Vec2d& pixel) const {
  const Vec3d d = world_direction(pixel);
  return {centre_, d * (1.0 / d.norm())};
}

std::unique_ptr<CameraModel> PinholeCamera::clone() const { return std::make_unique<PinholeCamera>(*this); }

}  // namespace tomorig::calibration
