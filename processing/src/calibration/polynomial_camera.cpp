#include "tomorig/processing/calibration/polynomial_camera.h"

#include <cmath>

#include <fmt/core.h>

#include "polynomial_maps.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

detail::MapForm form_of(PolynomialKind kind) {
  return kind == PolynomialKind::rational2 ? detail::MapForm{detail::Basis::quadratic, true}
                                           : detail::MapForm{detail::Basis::cubic, false};
}

const char* name_of(PolynomialKind kind) { return kind == PolynomialKind::rational2 ? "rational2" : "soloff3"; }

void check_coefficients(PolynomialKind kind, const std::vector<double>& c, const char* which) {
  const int expected = PolynomialCamera::coefficient_count(kind);
  if (static_cast<int>(c.size()) != expected)
    throw bad_input(fmt::format("{} camera: {} mapping has {} coefficients, expected {}", name_of(kind), which, c.size(),
                                expected));
  for (std::size_t k = 0; k < c.size(); ++k)
    if (!std::isfinite(c[k]))
      throw bad_input(fmt::format("{} camera: {} coefficient {} is {}", name_of(kind), which, k, c[k]));
}

}  // namespace

int PolynomialCamera::coefficient_count(PolynomialKind kind) { return form_of(kind).coefficient_count(); }

PolynomialCamera::PolynomialCamera(PolynomialKind kind, const Normalization& normalization, std::vector<double> forward,
                                   std::vector<double> inverse, int newton_steps)
    : kind_(kind), normalization_(normalization), forward_(std::move(forward)), inverse_(std::move(inverse)),
      newton_steps_(newton_steps) {
  check_coefficients(kind_, forward_, "forward");
  check_coefficients(kind_, inverse_, "inverse");
  const auto& n = normalization_;
  for (double v : {n.world_centre.x, n.world_centre.y, n.world_centre.z, n.image_centre.x, n.image_centre.y})
    if (!std::isfinite(v)) throw bad_input(fmt::format("{} camera: normalisation centre is not finite", name_of(kind_)));
  if (!(n.world_scale > 0) || !(n.image_scale > 0) || !std::isfinite(n.world_scale) || !std::isfinite(n.image_scale))
    throw bad_input(fmt::format("{} camera: normalisation scales must be finite and > 0", name_of(kind_)));
  if (newton_steps_ < 0) throw bad_input("polynomial camera: newton_steps must be >= 0");
}

std::string PolynomialCamera::model_name() const { return name_of(kind_); }

Vec2d PolynomialCamera::project(const Vec3d& world) const {
  const Vec3d n = normalization_.to_normalised(world);
  return normalization_.to_pixel(detail::evaluate_map(form_of(kind_), forward_.data(), n.x, n.y, n.z));
}

Vec3d PolynomialCamera::inverse_mapping(const Vec2d& pixel, double world_z) const {
  const Vec2d i = normalization_.to_normalised(pixel);
  const double zn = (world_z - normalization_.world_centre.z) / normalization_.world_scale;
  const Vec2d w = detail::evaluate_map(form_of(kind_), inverse_.data(), i.x, i.y, zn);
  Vec3d out = normalization_.to_world({w.x, w.y, zn});
  out.z = world_z;
  return out;
}

Vec3d PolynomialCamera::back_project(const Vec2d& pixel, double world_z) const {
  Vec3d x = inverse_mapping(pixel, world_z);
  // Newton on project(x, y, z) = pixel in (x, y), with a central-difference Jacobian; the
  // inverse mapping is already within a fraction of a pixel, so a few steps reach rounding.
  const double h = 1e-6 * normalization_.world_scale;
  for (int step = 0; step < newton_steps_; ++step) {
    const Vec2d f = project(x);
    const Vec2d e{f.x - pixel.x, f.y - pixel.y};
    if (std::hypot(e.x, e.y) < 1e-11 * normalization_.image_scale) break;
    const Vec2d fxp = project({x.x + h, x.y, world_z}), fxm = project({x.x - h, x.y, world_z});
    const Vec2d fyp = project({x.x, x.y + h, world_z}), fym = project({x.x, x.y - h, world_z});
    const double j11 = (fxp.x - fxm.x) / (2 * h), j21 = (fxp.y - fxm.y) / (2 * h);
    const double j12 = (fyp.x - fym.x) / (2 * h), j22 = (fyp.y - fym.y) / (2 * h);
    const double det = j11 * j22 - j12 * j21;
    if (!(std::abs(det) > 0)) break;
    x.x -= (j22 * e.x - j12 * e.y) / det;
    x.y -= (-j21 * e.x + j11 * e.y) / det;
  }
  return x;
}

Ray PolynomialCamera::line_of_sight(const Vec2d& pixel) const {
  const double z0 = normalization_.world_centre.z - normalization_.world_scale;
  const double z1 = normalization_.world_centre.z + normalization_.world_scale;
  const Vec3d a = back_project(pixel, z0), b = back_project(pixel, z1);
  const Vec3d d = b - a;
  return {a, d * (1.0 / d.norm())};
}

std::unique_ptr<CameraModel> PolynomialCamera::clone() const { return std::make_unique<PolynomialCamera>(*this); }

}  // namespace tomorig::calibration
