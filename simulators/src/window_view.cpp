#include "tomorig/simulators/window_view.h"

#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::sim {
namespace {

// Crosses a face with unit normal n (along the travel) from index n1 into n2: the tangential
// component of n1 * d is kept (Snell), the normal one follows from |d'| = 1.
Vec3d cross_face(const Vec3d& d, const Vec3d& n, double n1, double n2) {
  const Vec3d tangential = (d - n * n.dot(d)) * (n1 / n2);
  const double t2 = tangential.dot(tangential);
  if (t2 >= 1) throw runtime_error("window view: total internal reflection");
  return tangential + n * std::sqrt(1 - t2);
}

}  // namespace

Ray WindowView::medium_ray(const Vec2d& pixel) const {
  const Ray air = camera.line_of_sight(pixel);
  const Vec3d& n = window.normal;
  const double air_face = window.medium_face_mm - window.thickness_mm;
  const double cos_air = n.dot(air.direction);
  if (!(cos_air > 0)) throw runtime_error("window view: the pixel's ray points away from the window");
  const Vec3d p1 = air.origin + air.direction * ((air_face - n.dot(air.origin)) / cos_air);
  const Vec3d d2 = cross_face(air.direction, n, window.n_air, window.n_window);
  const Vec3d p2 = p1 + d2 * (window.thickness_mm / n.dot(d2));
  const Vec3d d3 = cross_face(d2, n, window.n_window, window.n_medium);
  return {p2, d3};
}

Vec3d WindowView::back_project(const Vec2d& pixel, double world_z) const {
  const Ray r = medium_ray(pixel);
  Vec3d p = r.origin + r.direction * ((world_z - r.origin.z) / r.direction.z);
  p.z = world_z;
  return p;
}

Vec2d WindowView::project(const Vec3d& world) const {
  // Newton on the pixel: where its medium ray meets the plane through `world` across the
  // normal, minus `world`, in two directions across the normal; Jacobian by differences.
  const Vec3d& n = window.normal;
  const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  Vec3d a = helper - n * n.dot(helper);
  a = a * (1.0 / a.norm());
  const Vec3d b{n.y * a.z - n.z * a.y, n.z * a.x - n.x * a.z, n.x * a.y - n.y * a.x};
  const double depth = n.dot(world);
  auto miss = [&](const Vec2d& u) {
    const Ray r = medium_ray(u);
    const Vec3d hit = r.origin + r.direction * ((depth - n.dot(r.origin)) / n.dot(r.direction));
    const Vec3d d = hit - world;
    return Vec2d{a.dot(d), b.dot(d)};
  };
  Vec2d u = camera.project(world);  // the view without the window: a start within pixels
  for (int iteration = 0; iteration < 30; ++iteration) {
    const Vec2d m = miss(u);
    constexpr double h = 1e-3;
    const Vec2d mx = miss({u.x + h, u.y}), my = miss({u.x, u.y + h});
    const double j11 = (mx.x - m.x) / h, j21 = (mx.y - m.y) / h, j12 = (my.x - m.x) / h, j22 = (my.y - m.y) / h;
    const double det = j11 * j22 - j12 * j21;
    const double dx = (j22 * m.x - j12 * m.y) / det, dy = (j11 * m.y - j21 * m.x) / det;
    u = {u.x - dx, u.y - dy};
    if (std::hypot(m.x, m.y) < 1e-13 && std::hypot(dx, dy) < 1e-10) return u;
  }
  if (std::hypot(miss(u).x, miss(u).y) < 1e-9) return u;
  throw runtime_error(fmt::format("window view: no pixel sees ({}, {}, {}) mm through the window", world.x, world.y, world.z));
}

}  // namespace tomorig::sim
