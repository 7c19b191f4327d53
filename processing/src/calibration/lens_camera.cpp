#include "tomorig/processing/calibration/lens_camera.h"

#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {

Vec2d LensDistortion::distort(const Vec2d& ideal) const {
  const double x = ideal.x, y = ideal.y;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  return {x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x), y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y};
}

Vec2d LensDistortion::undistort(const Vec2d& distorted) const {
  Vec2d u = distorted;
  for (int iteration = 0; iteration < 50; ++iteration) {
    const double x = u.x, y = u.y;
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
    const double dradial = k1 + r2 * (2 * k2 + 3 * k3 * r2);  // d radial / d r²
    const Vec2d d = distort(u);
    const double fx = d.x - distorted.x, fy = d.y - distorted.y;
    // Jacobian of distort at u.
    const double a = radial + 2 * x * x * dradial + 2 * p1 * y + 6 * p2 * x;
    const double b = 2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y;
    const double c = 2 * x * y * dradial + 2 * p1 * x + 2 * p2 * y;
    const double e = radial + 2 * y * y * dradial + 6 * p1 * y + 2 * p2 * x;
    const double det = a * e - b * c;
    if (!(std::abs(det) > 1e-12)) break;
    const double dx = (e * fx - b * fy) / det, dy = (a * fy - c * fx) / det;
    u = {u.x - dx, u.y - dy};
    if (std::abs(dx) + std::abs(dy) < 1e-15 * (1 + std::abs(u.x) + std::abs(u.y))) return u;
  }
  const Vec2d check = distort(u);
  if (std::hypot(check.x - distorted.x, check.y - distorted.y) < 1e-12 * (1 + std::hypot(distorted.x, distorted.y)))
    return u;
  throw runtime_error(fmt::format("lens distortion: the image point ({}, {}) (normalised) cannot be undistorted: it lies "
                                  "beyond where the lens model folds over",
                                  distorted.x, distorted.y));
}

LensCamera::LensCamera(const PinholeParameters& pinhole, const LensDistortion& d) : pinhole_(pinhole), distortion_(d) {
  for (double v : {d.k1, d.k2, d.k3, d.p1, d.p2})
    if (!std::isfinite(v)) throw bad_input("pinhole_distortion camera: every distortion coefficient must be finite");
}

Vec2d LensCamera::project(const Vec3d& world) const {
  const auto& p = pinhole_.parameters();
  const Vec3d c = pinhole_.to_camera(world);
  const Vec2d d = distortion_.distort({c.x / c.z, c.y / c.z});
  return {p.fx * d.x + p.cx, p.fy * d.y + p.cy};
}

Vec2d LensCamera::ideal_pixel(const Vec2d& pixel) const {
  const auto& p = pinhole_.parameters();
  const Vec2d ideal = distortion_.undistort({(pixel.x - p.cx) / p.fx, (pixel.y - p.cy) / p.fy});
  return {p.fx * ideal.x + p.cx, p.fy * ideal.y + p.cy};
}

Vec3d LensCamera::back_project(const Vec2d& pixel, double world_z) const {
  return pinhole_.back_project(ideal_pixel(pixel), world_z);
}

Ray LensCamera::line_of_sight(const Vec2d& pixel) const { return pinhole_.line_of_sight(ideal_pixel(pixel)); }

std::unique_ptr<CameraModel> LensCamera::clone() const { return std::make_unique<LensCamera>(*this); }

}  // namespace tomorig::calibration
