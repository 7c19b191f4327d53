#include "tomorig/processing/optics/droplet_image.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::optics {
namespace {

void check(double d, double chi, double tau) {
  if (!(d >= 0.0) || !std::isfinite(d)) throw bad_input(fmt::format("droplet diameter {} must be >= 0", d));
  if (!(chi > 0.0) || !std::isfinite(chi))
    throw bad_input(fmt::format("point-spread half-width chi = {} must be > 0", chi));
  if (!(tau >= 0.0 && tau <= 1.0)) throw bad_input(fmt::format("droplet transmission tau = {} must be in [0, 1]", tau));
}

// exp(-z) I0(z) for z >= 0: finite where I0 alone overflows.
double scaled_bessel_i0(double z) {
  if (z < 500.0) return std::cyl_bessel_i(0.0, z) * std::exp(-z);
  const double inv = 1.0 / (8.0 * z);  // asymptotic series, terms 1, 1/(8z), 9/(2 (8z)^2)
  return (1.0 + inv + 4.5 * inv * inv) / std::sqrt(2.0 * M_PI * z);
}

}  // namespace

double shadow_profile(double r, double d, double chi, double tau) {
  check(d, chi, tau);
  if (!(r >= 0.0) || !std::isfinite(r)) throw bad_input(fmt::format("radius r = {} must be >= 0", r));
  const double rt = std::sqrt(2.0) * r / chi;
  const double at = std::sqrt(2.0) * 0.5 * d / chi;
  if (at == 0.0) return 1.0;
  // exp(-r~^2 - rho^2) I0(2 r~ rho) = exp(-(r~ - rho)^2) [exp(-2 r~ rho) I0(2 r~ rho)]: the
  // integrand in a form that never overflows. It is smooth with one peak near rho = r~ of
  // width ~1: Simpson on steps of at most 0.02 is exact to ~1e-9.
  int steps = static_cast<int>(std::ceil(at / 0.02));
  steps = std::max(steps + steps % 2, 2);
  const double h = at / steps;
  double sum = 0.0;
  for (int i = 0; i <= steps; ++i) {
    const double rho = i * h;
    const double f = std::exp(-(rt - rho) * (rt - rho)) * scaled_bessel_i0(2.0 * rt * rho) * rho;
    sum += (i == 0 || i == steps ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0)) * f;
  }
  return 1.0 - 2.0 * (1.0 - tau) * sum * h / 3.0;
}

double minimum_intensity(double d, double chi, double tau) {
  check(d, chi, tau);
  const double at = std::sqrt(2.0) * 0.5 * d / chi;
  return 1.0 - (1.0 - tau) * (1.0 - std::exp(-at * at));
}

double object_numerical_aperture(double f_number, double magnification) {
  if (!(f_number > 0.0) || !std::isfinite(f_number))
    throw bad_input(fmt::format("f-number {} must be > 0", f_number));
  if (!(magnification > 0.0) || !std::isfinite(magnification))
    throw bad_input(fmt::format("magnification {} must be > 0", magnification));
  return 1.0 / (2.0 * f_number * (1.0 + 1.0 / magnification));
}

}  // namespace tomorig::optics
