#include "tomorig/processing/calibration/two_plane_camera.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "polynomial_maps.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

constexpr detail::MapForm kPlaneForm{detail::Basis::cubic_2d, false};

void check_mapping(const std::vector<double>& c, double z, const char* which) {
  if (static_cast<int>(c.size()) != TwoPlaneCamera::kCoefficientsPerMapping)
    throw bad_input(fmt::format("twoplane camera: plane z = {} mm: {} mapping has {} coefficients, expected {}", z, which,
                                c.size(), TwoPlaneCamera::kCoefficientsPerMapping));
  for (std::size_t k = 0; k < c.size(); ++k)
    if (!std::isfinite(c[k]))
      throw bad_input(fmt::format("twoplane camera: plane z = {} mm: {} coefficient {} is {}", z, which, k, c[k]));
}

}  // namespace

TwoPlaneCamera::TwoPlaneCamera(const Normalization& normalization, std::vector<TwoPlaneMapping> planes, int newton_steps)
    : normalization_(normalization), planes_(std::move(planes)), newton_steps_(newton_steps) {
  if (planes_.size() < 2)
    throw bad_input(fmt::format("twoplane camera: {} plane(s) given; the model needs at least 2", planes_.size()));
  std::sort(planes_.begin(), planes_.end(), [](const auto& a, const auto& b) { return a.z < b.z; });
  for (std::size_t k = 0; k < planes_.size(); ++k) {
    if (!std::isfinite(planes_[k].z)) throw bad_input("twoplane camera: a plane z is not finite");
    if (k > 0 && planes_[k].z == planes_[k - 1].z)
      throw bad_input(fmt::format("twoplane camera: two planes share z = {} mm", planes_[k].z));
    check_mapping(planes_[k].to_world, planes_[k].z, "to_world");
    check_mapping(planes_[k].to_image, planes_[k].z, "to_image");
  }
  const auto& n = normalization_;
  if (!(n.world_scale > 0) || !(n.image_scale > 0) || !std::isfinite(n.world_scale) || !std::isfinite(n.image_scale))
    throw bad_input("twoplane camera: normalisation scales must be finite and > 0");
  if (newton_steps_ < 0) throw bad_input("twoplane camera: newton_steps must be >= 0");
}

Vec3d TwoPlaneCamera::back_project(const Vec2d& pixel, double world_z) const {
  // Least-squares straight line x(z), y(z) through the per-plane points (exact for two planes).
  // Since sum(z_k - zm) = 0, the slope sum((z_k - zm) x_k) / sum((z_k - zm)^2) needs no
  // second pass and nothing is stored (project() calls this in its Newton loop).
  const Vec2d i = normalization_.to_normalised(pixel);
  const double count = static_cast<double>(planes_.size());
  double zm = 0;
  for (const auto& plane : planes_) zm += plane.z / count;
  double xm = 0, ym = 0, szz = 0, szx = 0, szy = 0;
  for (const auto& plane : planes_) {
    const Vec2d w = detail::evaluate_map(kPlaneForm, plane.to_world.data(), i.x, i.y, 0);
    const double x = w.x * normalization_.world_scale + normalization_.world_centre.x;
    const double y = w.y * normalization_.world_scale + normalization_.world_centre.y;
    const double dz = plane.z - zm;
    xm += x / count;
    ym += y / count;
    szz += dz * dz;
    szx += dz * x;
    szy += dz * y;
  }
  const double sx = szx / szz, sy = szy / szz;
  return {xm + sx * (world_z - zm), ym + sy * (world_z - zm), world_z};
}

Ray TwoPlaneCamera::line_of_sight(const Vec2d& pixel) const {
  const Vec3d a = back_project(pixel, planes_.front().z), b = back_project(pixel, planes_.back().z);
  const Vec3d d = b - a;
  return {a, d * (1.0 / d.norm())};
}

Vec2d TwoPlaneCamera::project(const Vec3d& world) const {
  // Start: the to_image maps of the two planes nearest in z, interpolated linearly in z.
  std::size_t k = 0;
  while (k + 2 < planes_.size() && planes_[k + 1].z < world.z) ++k;
  const auto& p0 = planes_[k];
  const auto& p1 = planes_[k + 1];
  const double s = (world.z - p0.z) / (p1.z - p0.z);
  const Vec3d n = normalization_.to_normalised(world);
  const Vec2d i0 = detail::evaluate_map(kPlaneForm, p0.to_image.data(), n.x, n.y, 0);
  const Vec2d i1 = detail::evaluate_map(kPlaneForm, p1.to_image.data(), n.x, n.y, 0);
  Vec2d u = normalization_.to_pixel({i0.x + s * (i1.x - i0.x), i0.y + s * (i1.y - i0.y)});
  // Newton on back_project(u, z) = (x, y): the pixel whose line of sight meets the point.
  const double h = 1e-3;  // pixels; back_project is smooth, central differences
  for (int step = 0; step < newton_steps_; ++step) {
    const Vec3d b = back_project(u, world.z);
    const Vec2d e{b.x - world.x, b.y - world.y};
    if (std::hypot(e.x, e.y) < 1e-13 * normalization_.world_scale) break;
    const Vec3d bxp = back_project({u.x + h, u.y}, world.z), bxm = back_project({u.x - h, u.y}, world.z);
    const Vec3d byp = back_project({u.x, u.y + h}, world.z), bym = back_project({u.x, u.y - h}, world.z);
    const double j11 = (bxp.x - bxm.x) / (2 * h), j21 = (bxp.y - bxm.y) / (2 * h);
    const double j12 = (byp.x - bym.x) / (2 * h), j22 = (byp.y - bym.y) / (2 * h);
    const double det = j11 * j22 - j12 * j21;
    if (!(std::abs(det) > 0)) break;
    u.x -= (j22 * e.x - j12 * e.y) / det;
    u.y -= (-j21 * e.x + j11 * e.y) / det;
  }
  return u;
}

std::unique_ptr<CameraModel> TwoPlaneCamera::clone() const { return std::make_unique<TwoPlaneCamera>(*this); }

}  // namespace tomorig::calibration
