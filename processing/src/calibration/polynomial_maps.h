#pragma once
// The mappings behind the camera models: three normalised inputs (p, q, r) -> two normalised
// outputs, either a polynomial (one coefficient row per output) or a ratio of polynomials
// with a shared denominator (rows: first numerator, second numerator, denominator).
// Internal to the calibration code; the monomial orders are documented in the public headers.
#include <array>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::calibration::detail {

constexpr int kMaxTerms = 20;
using Terms = std::array<double, kMaxTerms>;

enum class Basis { linear, quadratic, cubic, cubic_2d };

// [p, q, r, 1]: the columns of the DLT matrix (Eq. 2.1).
inline int linear_terms(double p, double q, double r, Terms& m) {
  m[0] = p, m[1] = q, m[2] = r, m[3] = 1;
  return 4;
}

// [p^2, pq, pr, p, q^2, qr, q, r^2, r, 1]: b_k1..b_k10 of Eq. A.4.
inline int quadratic_terms(double p, double q, double r, Terms& m) {
  m[0] = p * p, m[1] = p * q, m[2] = p * r, m[3] = p, m[4] = q * q;
  m[5] = q * r, m[6] = q, m[7] = r * r, m[8] = r, m[9] = 1;
  return 10;
}

// Eq. A.5 order, plus r^2 q at the end.
inline int cubic_terms(double p, double q, double r, Terms& m) {
  m[0] = 1, m[1] = p, m[2] = q, m[3] = r;
  m[4] = p * p, m[5] = q * q, m[6] = r * r, m[7] = p * q, m[8] = p * r, m[9] = q * r;
  m[10] = p * p * p, m[11] = q * q * q, m[12] = r * r * r, m[13] = p * p * q, m[14] = p * p * r;
  m[15] = q * q * p, m[16] = q * q * r, m[17] = r * r * p, m[18] = p * q * r, m[19] = r * r * q;
  return 20;
}

// [1, p, q, p^2, pq, q^2, p^3, p^2 q, p q^2, q^3] (r ignored): the two-plane model's maps.
inline int cubic_2d_terms(double p, double q, double /*r*/, Terms& m) {
  m[0] = 1, m[1] = p, m[2] = q, m[3] = p * p, m[4] = p * q, m[5] = q * q;
  m[6] = p * p * p, m[7] = p * p * q, m[8] = p * q * q, m[9] = q * q * q;
  return 10;
}

inline int basis_terms(Basis b, double p, double q, double r, Terms& m) {
  switch (b) {
    case Basis::linear: return linear_terms(p, q, r, m);
    case Basis::quadratic: return quadratic_terms(p, q, r, m);
    case Basis::cubic: return cubic_terms(p, q, r, m);
    case Basis::cubic_2d: return cubic_2d_terms(p, q, r, m);
  }
  return 0;
}

inline int basis_size(Basis b) {
  Terms m;
  return basis_terms(b, 0, 0, 0, m);
}

struct MapForm {
  Basis basis;
  bool rational;  // ratio with a shared denominator, whose constant term is fixed to 1
  int coefficient_count() const { return basis_size(basis) * (rational ? 3 : 2); }
};

// Matching inputs (p, q, r) and targets (two outputs), one row per point.
struct MapSamples {
  std::vector<std::array<double, 3>> inputs;
  std::vector<Vec2d> targets;
};

// Evaluates the mapping with coefficients c (coefficient_count() values).
inline Vec2d evaluate_map(const MapForm& form, const double* c, double p, double q, double r) {
  Terms m;
  const int n = basis_terms(form.basis, p, q, r, m);
  double a = 0, b = 0, d = 0;
  for (int k = 0; k < n; ++k) {
    a += c[k] * m[k];
    b += c[n + k] * m[k];
  }
  if (!form.rational) return {a, b};
  for (int k = 0; k < n; ++k) d += c[2 * n + k] * m[k];
  return {a / d, b / d};
}

}  // namespace tomorig::calibration::detail
