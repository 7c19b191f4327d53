#pragma once
// A small Levenberg-Marquardt solver (Marquardt's diagonal scaling) for the calibration fits:
// minimises |r(p)|^2 for a residual vector r of a parameter vector p. Internal: uses Eigen.
#include <functional>

#include <Eigen/Dense>

namespace tomorig::calibration::detail {

// Fills r (size: residuals) and, when J is not null, the Jacobian dr/dp (residuals x params).
using ResidualFunction = std::function<void(const Eigen::VectorXd& p, Eigen::VectorXd& r, Eigen::MatrixXd* J)>;

struct LmSettings {
  int max_iterations = 200;
  double tolerance = 1e-10;  // relative cost decrease / relative step size
};

struct LmResult {
  int iterations = 0;
  bool converged = false;
  double cost = 0;  // |r|^2 at the returned p
  // Smallest over largest eigenvalue of J^T J at the returned p, after column scaling: ~0 when
  // the data do not determine every parameter.
  double conditioning = 0;
};

LmResult levenberg_marquardt(const ResidualFunction& f, int residual_count, Eigen::VectorXd& p,
                             const LmSettings& settings);

// Central-difference Jacobian, for residual functions without an analytic one.
void numeric_jacobian(const ResidualFunction& f, const Eigen::VectorXd& p, int residual_count, Eigen::MatrixXd& J);

}  // namespace tomorig::calibration::detail
