// The higher-order models of thesis Appendix A.2.2 and their inverse mappings.
#include <fmt/core.h>

#include "identifiability.h"
#include "mapping_fit.h"
#include "model_fits.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration::detail {
namespace {

struct Samples {
  MapSamples forward;  // (x~, y~, z~) -> (x~_I, y~_I)
  MapSamples inverse;  // (x~_I, y~_I, z~) -> (x~, y~): roles swapped, z stays an input
};

Samples samples_of(std::span<const PointCorrespondence> points, const Normalization& n) {
  Samples s;
  for (const auto& p : points) {
    const Vec3d w = n.to_normalised(p.world);
    const Vec2d i = n.to_normalised(p.pixel);
    s.forward.inputs.push_back({w.x, w.y, w.z});
    s.forward.targets.push_back(i);
    s.inverse.inputs.push_back({i.x, i.y, w.z});
    s.inverse.targets.push_back({w.x, w.y});
  }
  return s;
}

// Eq. A.4 started from the DLT as the thesis does: b14 = a11, b17 = a12, b19 = a13,
// b110 = a14 (and likewise for rows 2 and 3), all second-order terms 0.
std::vector<double> rational2_from_dlt(const std::vector<double>& a) {
  std::vector<double> b(30, 0.0);
  for (int row = 0; row < 3; ++row) {
    b[10 * row + 3] = a[4 * row + 0];  // p
    b[10 * row + 6] = a[4 * row + 1];  // q
    b[10 * row + 8] = a[4 * row + 2];  // r
    b[10 * row + 9] = a[4 * row + 3];  // 1
  }
  b[29] = 1;  // a34 = 1 already; kept exact
  return b;
}

// Eq. A.5 started as the thesis does: a1 = a20 = 1 (the first output follows the first
// input, the second the second), everything else 0.
std::vector<double> soloff3_identity() {
  std::vector<double> a(40, 0.0);
  a[1] = 1;
  a[20 + 2] = 1;
  return a;
}

}  // namespace

std::unique_ptr<CameraModel> fit_polynomial(PolynomialKind kind, std::span<const PointCorrespondence> points,
                                            const FitOptions& options, FitReport& report) {
  const bool rational = kind == PolynomialKind::rational2;
  const std::string model = rational ? "rational2" : "soloff3";
  const MapForm form = rational ? MapForm{Basis::quadratic, true} : MapForm{Basis::cubic, false};
  const int unknowns = rational ? 29 : 40;
  // z^2 terms need 3 planes; the z^3 term of Eq. A.5 needs 4.
  const Normalization n = check_points(points, {model, unknowns, rational ? 3 : 4, 0, form.basis}, options);
  const Samples s = samples_of(points, n);
  const LmSettings settings = lm_settings(options);

  std::vector<double> forward_start, inverse_start;
  if (rational) {
    // The DLT is only the starting point: it need not converge itself.
    FitOptions start_options = options;
    start_options.require_convergence = false;
    forward_start = rational2_from_dlt(estimate_dlt(points, n, start_options).normalised);
    // The inverse of a DLT at fixed z is itself a ratio of 2nd-order polynomials in
    // (x_I, y_I, z), so the algebraic (linear) fit starts next to the optimum.
    inverse_start = algebraic_rational_start(form, s.inverse);
  } else {
    forward_start = inverse_start = soloff3_identity();
  }
  MapFit forward = fit_map(form, s.forward, forward_start, settings);
  if (rational && !forward.lm.converged) {
    // A second start: the algebraic fit of the projection itself (exact on data that lie on
    // such a mapping), which often sits closer to the optimum than the DLT does.
    MapFit second = fit_map(form, s.forward, algebraic_rational_start(form, s.forward), settings);
    if (second.lm.converged || second.lm.cost < forward.lm.cost) forward = std::move(second);
  }
  check_fit(forward.lm, unknowns, model, "projection", options, !rational);
  const MapFit inverse = fit_map(form, s.inverse, inverse_start, settings);
  check_fit(inverse.lm, unknowns, model, "inverse mapping", options, !rational);
  // A ratio must not have a pole inside the box it was calibrated over.
  require_one_signed_denominator(form, forward.coefficients, s.forward, model, "projection", n, true, points, options);
  require_one_signed_denominator(form, inverse.coefficients, s.inverse, model, "inverse mapping", n, false, points, options);

  report.normalization = n;
  report.iterations = forward.lm.iterations;
  report.converged = forward.lm.converged && inverse.lm.converged;
  auto camera = std::make_unique<PolynomialCamera>(kind, n, forward.coefficients, inverse.coefficients, options.newton_steps);
  double inverse_sum = 0;
  for (const auto& p : points) inverse_sum += (camera->inverse_mapping(p.pixel, p.world.z) - p.world).norm();
  report.inverse_mapping_mean_um = 1000.0 * inverse_sum / static_cast<double>(points.size());
  return camera;
}

}  // namespace tomorig::calibration::detail
