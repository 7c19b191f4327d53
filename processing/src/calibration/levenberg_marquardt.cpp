#include "levenberg_marquardt.h"

#include <algorithm>
#include <cmath>

namespace tomorig::calibration::detail {
namespace {

// Eigenvalue ratio of the column-scaled normal matrix: scaling first, so that parameters of
// very different sizes do not look degenerate.
double scaled_conditioning(const Eigen::MatrixXd& JtJ) {
  const Eigen::VectorXd d = JtJ.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd S = d.asDiagonal() * JtJ * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S, Eigen::EigenvaluesOnly);
  const auto& ev = eig.eigenvalues();
  if (ev.size() == 0 || ev(ev.size() - 1) <= 0) return 0;
  return std::max(ev(0), 0.0) / ev(ev.size() - 1);
}

// J^T J as a symmetric rank update. Not J.transpose() * J: that is Eigen's general product,
// which runs on OpenMP threads in this library, and on a loaded machine their spin-waiting
// costs 10-50x the arithmetic of these small systems.
Eigen::MatrixXd normal_matrix(const Eigen::MatrixXd& J) {
  Eigen::MatrixXd JtJ = Eigen::MatrixXd::Zero(J.cols(), J.cols());
  JtJ.selfadjointView<Eigen::Lower>().rankUpdate(J.transpose());
  return JtJ.selfadjointView<Eigen::Lower>();
}

}  // namespace

void numeric_jacobian(const ResidualFunction& f, const Eigen::VectorXd& p, int residual_count, Eigen::MatrixXd& J) {
  J.resize(residual_count, p.size());
  Eigen::VectorXd q = p, r_plus(residual_count), r_minus(residual_count);
  for (int k = 0; k < p.size(); ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(p(k)));
    q(k) = p(k) + h;
    f(q, r_plus, nullptr);
    q(k) = p(k) - h;
    f(q, r_minus, nullptr);
    q(k) = p(k);
    J.col(k) = (r_plus - r_minus) / (2 * h);
  }
}

LmResult levenberg_marquardt(const ResidualFunction& f, int residual_count, Eigen::VectorXd& p,
                             const LmSettings& settings) {
  LmResult result;
  Eigen::VectorXd r(residual_count), r_new(residual_count);
  Eigen::MatrixXd J;
  f(p, r, &J);
  double cost = r.squaredNorm();
  double lambda = 1e-3;  // relative to each parameter's own curvature (Marquardt scaling)
  for (result.iterations = 0; result.iterations < settings.max_iterations;) {
    const Eigen::MatrixXd JtJ = normal_matrix(J);
    const Eigen::VectorXd g = J.transpose() * r;
    // A zero residual or a zero gradient: nothing left to improve.
    if (cost == 0 || g.lpNorm<Eigen::Infinity>() <= 1e-300) {
      result.converged = true;
      break;
    }
    // Marquardt scaling: damp each parameter in proportion to its own curvature, with a
    // floor so that a parameter the data do not see still gets a finite step.
    Eigen::VectorXd diag = JtJ.diagonal();
    const double floor = 1e-12 * std::max(diag.maxCoeff(), 1e-300);
    diag = diag.cwiseMax(floor);
    ++result.iterations;
    bool improved = false;
    while (lambda < 1e16) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal() += lambda * diag;
      const Eigen::VectorXd step = A.ldlt().solve(-g);
      const Eigen::VectorXd p_new = p + step;
      f(p_new, r_new, nullptr);
      const double cost_new = r_new.squaredNorm();
      if (std::isfinite(cost_new) && cost_new < cost) {
        const double decrease = (cost - cost_new) / cost;
        const double step_size = step.norm() / (p.norm() + 1e-300);
        p = p_new;
        cost = cost_new;
        lambda = std::max(lambda / 10, 1e-15);
        improved = true;
        if (decrease <= settings.tolerance || step_size <= settings.tolerance) result.converged = true;
        break;
      }
      lambda *= 10;
    }
    // No step of any damping decreases the cost: p is a minimum to rounding precision.
    if (!improved) result.converged = true;
    if (result.converged) break;
    f(p, r, &J);
  }
  f(p, r, &J);
  result.cost = r.squaredNorm();
  result.conditioning = scaled_conditioning(normal_matrix(J));
  return result;
}

}  // namespace tomorig::calibration::detail
