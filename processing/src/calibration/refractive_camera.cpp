#include "tomorig/processing/calibration/refractive_camera.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

// Snell's law in vector form: the unit direction d crossing a face with unit normal n
// (n . d > 0) from index n_i into n_t, eta = n_i / n_t. Returns false for total reflection.
bool refract(const Vec3d& d, const Vec3d& n, double eta, Vec3d& out) {
  const double cos_i = n.dot(d);
  const double sin2_t = eta * eta * (1 - cos_i * cos_i);
  if (sin2_t >= 1) return false;
  out = d * eta + n * (std::sqrt(1 - sin2_t) - eta * cos_i);
  out = out * (1.0 / out.norm());
  return true;
}

}  // namespace

std::string FlatWindow::validate() const {
  for (double n : {n_air, n_window, n_medium})
    if (!std::isfinite(n) || n < 1 || n > 5)
      return fmt::format("refractive index {} is invalid: every index must be in [1, 5]", n);
  if (!std::isfinite(thickness_mm) || thickness_mm < 0)
    return fmt::format("window thickness {} mm is invalid: it must be >= 0", thickness_mm);
  if (!std::isfinite(medium_face_mm)) return "the window's medium face position must be finite";
  if (!(std::abs(normal.norm() - 1) < 1e-9))
    return fmt::format("window normal ({}, {}, {}) is invalid: it must have unit length", normal.x, normal.y, normal.z);
  return {};
}

RefractiveCamera::RefractiveCamera(const LensCamera& lens, const FlatWindow& window)
    : lens_(lens), window_(window), centre_(lens.pinhole().centre()) {
  if (const std::string problem = window.validate(); !problem.empty())
    throw bad_input("refractive camera: " + problem);
  const double air_face = window.medium_face_mm - window.thickness_mm;
  if (!(window.normal.dot(centre_) < air_face))
    throw bad_input(fmt::format("refractive camera: the projection centre ({:.4g}, {:.4g}, {:.4g}) mm is not on the air "
                                "side of the window (normal . X = {:.4g} there, the air face is at {:.4g}); the window "
                                "normal must point from the camera into the medium",
                                centre_.x, centre_.y, centre_.z, window.normal.dot(centre_), air_face));
}

Vec3d RefractiveCamera::air_direction(const Vec3d& world) const {
  const Vec3d& n = window_.normal;
  const Vec3d v = world - centre_;
  const double along = n.dot(v);
  const Vec3d radial_vector = v - n * along;
  const double R = radial_vector.norm();
  if (R < 1e-300 * std::max(1.0, std::abs(along)) || along <= 0) return v * (1.0 / v.norm());
  // Heights of the path in each layer, along the normal.
  const double a_c = n.dot(centre_), a_x = a_c + along;
  const double air_face = window_.medium_face_mm - window_.thickness_mm, medium_face = window_.medium_face_mm;
  const double h[3] = {std::min(a_x, air_face) - a_c, std::max(0.0, std::min(a_x, medium_face) - std::max(a_c, air_face)),
                       std::max(0.0, a_x - medium_face)};
  // sin(angle in layer i) = ratio[i] * s, s the sine in air.
  const double ratio[3] = {1.0, window_.n_air / window_.n_window, window_.n_air / window_.n_medium};
  double hi = 1.0;
  for (int i = 0; i < 3; ++i)
    if (h[i] > 0) hi = std::min(hi, 1.0 / ratio[i]);
  double lo = 0;
  // Offset across the normal reached with air sine s, minus the offset wanted; increasing in s.
  auto offset = [&](double s, double& slope) {
    double g = -R;
    slope = 0;
    for (int i = 0; i < 3; ++i) {
      if (h[i] <= 0) continue;
      const double a = ratio[i], c2 = 1 - a * a * s * s;
      const double c = std::sqrt(std::max(c2, 1e-300));
      g += h[i] * a * s / c;
      slope += h[i] * a / (c2 * c);
    }
    return g;
  };
  double s = std::min(R / v.norm(), 0.5 * (lo + hi));  // the straight line's sine: a close start
  for (int iteration = 0; iteration < 100; ++iteration) {
    double slope = 0;
    const double g = offset(s, slope);
    if (g > 0) hi = s;
    else lo = s;
    double next = s - g / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket: bisect
    const double step = std::abs(next - s);
    s = next;
    if (step <= 1e-16 * std::max(s, 1e-300) || hi - lo <= 1e-17) break;
  }
  const Vec3d e = radial_vector * (1.0 / R);
  return n * std::sqrt(1 - s * s) + e * s;
}

Vec2d RefractiveCamera::project(const Vec3d& world) const {
  // Any point on the air ray images where the world point does; one at the point's distance
  // keeps the pinhole's arithmetic at the scale of the scene.
  return lens_.project(centre_ + air_direction(world) * (world - centre_).norm());
}

Ray RefractiveCamera::line_of_sight(const Vec2d& pixel) const {
  const Ray air = lens_.line_of_sight(pixel);
  const Vec3d& n = window_.normal;
  const double cos_air = n.dot(air.direction);
  const double air_face = window_.medium_face_mm - window_.thickness_mm;
  Vec3d in_window, in_medium;
  if (!(cos_air > 1e-12) || !refract(air.direction, n, window_.n_air / window_.n_window, in_window) ||
      !refract(in_window, n, window_.n_window / window_.n_medium, in_medium))
    throw runtime_error(fmt::format("refractive camera: the ray of pixel ({}, {}) does not reach the medium through the "
                                    "window (it points away from it or is totally reflected)",
                                    pixel.x, pixel.y));
  const Vec3d on_air_face = air.origin + air.direction * ((air_face - n.dot(air.origin)) / cos_air);
  const Vec3d on_medium_face = on_air_face + in_window * (window_.thickness_mm / n.dot(in_window));
  return {on_medium_face, in_medium};
}

Vec3d RefractiveCamera::back_project(const Vec2d& pixel, double world_z) const {
  const Ray ray = line_of_sight(pixel);
  if (std::abs(ray.direction.z) < 1e-12)
    throw runtime_error(fmt::format("refractive camera: the line of sight through pixel ({}, {}) is parallel to the plane "
                                    "z = {} mm",
                                    pixel.x, pixel.y, world_z));
  Vec3d point = ray.origin + ray.direction * ((world_z - ray.origin.z) / ray.direction.z);
  point.z = world_z;
  return point;
}

std::unique_ptr<CameraModel> RefractiveCamera::clone() const { return std::make_unique<RefractiveCamera>(*this); }

}  // namespace tomorig::calibration
