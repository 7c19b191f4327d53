#include "mapping_fit.h"

namespace tomorig::calibration::detail {

MapFit fit_map(const MapForm& form, const MapSamples& samples, std::vector<double> initial, const LmSettings& settings) {
  const int n = basis_size(form.basis);
  const int total = form.coefficient_count();
  // Free parameters: everything but a rational form's denominator constant (the last value).
  const int free = form.rational ? total - 1 : total;
  const int count = static_cast<int>(samples.inputs.size());

  auto full = [&](const Eigen::VectorXd& p) {
    std::vector<double> c(initial);
    for (int k = 0; k < free; ++k) c[k] = p(k);
    return c;
  };
  const ResidualFunction residuals = [&](const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    const std::vector<double> c = full(p);
    r.resize(2 * count);
    if (J) J->setZero(2 * count, free);
    Terms m;
    for (int i = 0; i < count; ++i) {
      const auto& in = samples.inputs[i];
      basis_terms(form.basis, in[0], in[1], in[2], m);
      double a = 0, b = 0, d = 1;
      for (int k = 0; k < n; ++k) {
        a += c[k] * m[k];
        b += c[n + k] * m[k];
      }
      if (form.rational) {
        d = 0;
        for (int k = 0; k < n; ++k) d += c[2 * n + k] * m[k];
      }
      const double inv_d = 1.0 / d;
      r(2 * i) = a * inv_d - samples.targets[i].x;
      r(2 * i + 1) = b * inv_d - samples.targets[i].y;
      if (!J) continue;
      for (int k = 0; k < n; ++k) {
        (*J)(2 * i, k) = m[k] * inv_d;
        (*J)(2 * i + 1, n + k) = m[k] * inv_d;
      }
      if (form.rational)
        for (int k = 0; 2 * n + k < free; ++k) {  // the constant (last) term is fixed
          (*J)(2 * i, 2 * n + k) = -a * m[k] * inv_d * inv_d;
          (*J)(2 * i + 1, 2 * n + k) = -b * m[k] * inv_d * inv_d;
        }
    }
  };

  Eigen::VectorXd p(free);
  for (int k = 0; k < free; ++k) p(k) = initial[k];
  MapFit fit;
  fit.lm = levenberg_marquardt(residuals, 2 * count, p, settings);
  fit.coefficients = full(p);
  return fit;
}

std::vector<double> algebraic_rational_start(const MapForm& form, const MapSamples& samples) {
  const int n = basis_size(form.basis);
  const int free = 3 * n - 1;
  const int count = static_cast<int>(samples.inputs.size());
  // Rows: N_1(x) - y_1 (D(x) - 1) = y_1 and N_2(x) - y_2 (D(x) - 1) = y_2, since D's
  // constant term (the last monomial, 1) is fixed to 1.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * count, free);
  Eigen::VectorXd b(2 * count);
  Terms m;
  for (int i = 0; i < count; ++i) {
    const auto& in = samples.inputs[i];
    basis_terms(form.basis, in[0], in[1], in[2], m);
    const Vec2d y = samples.targets[i];
    for (int k = 0; k < n; ++k) {
      A(2 * i, k) = m[k];
      A(2 * i + 1, n + k) = m[k];
    }
    for (int k = 0; k < n - 1; ++k) {
      A(2 * i, 2 * n + k) = -y.x * m[k];
      A(2 * i + 1, 2 * n + k) = -y.y * m[k];
    }
    b(2 * i) = y.x;
    b(2 * i + 1) = y.y;
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(b);
  std::vector<double> c(3 * n);
  for (int k = 0; k < free; ++k) c[k] = x(k);
  c[3 * n - 1] = 1;
  return c;
}

}  // namespace tomorig::calibration::detail
