#include "particle_model.h"

#include <algorithm>
#include <array>
#include <functional>
#include <cmath>
#include <limits>
#include <numbers>

namespace tomorig::quicklook::detail {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSigmaMin = 0.2, kSigmaMax = 8.0;
constexpr int kTableSize = 1024;
constexpr int kSimpsonIntervals = 256;  // per half of the triangle; even

double normal_pdf(double x, double s) {
  return std::exp(-0.5 * (x / s) * (x / s)) / (s * std::sqrt(2.0 * std::numbers::pi));
}

// sigma on a log scale over [kSigmaMin, kSigmaMax].
double table_sigma(int n) {
  return kSigmaMin * std::pow(kSigmaMax / kSigmaMin, static_cast<double>(n) / (kTableSize - 1));
}

struct LagRatioTable {
  std::array<double, kTableSize> ratio{};  // h(1) / h(2), decreasing with sigma
  LagRatioTable() {
    for (int n = 0; n < kTableSize; ++n) {
      const double s = table_sigma(n);
      ratio[static_cast<std::size_t>(n)] = pixel_autocorrelation(1.0, s) / pixel_autocorrelation(2.0, s);
    }
  }
};

const LagRatioTable& lag_ratio_table() {
  static const LagRatioTable table;  // built once, thread-safe
  return table;
}

}  // namespace

double pixel_autocorrelation(double lag, double sigma_px) {
  // Simpson's rule on each half of the triangle (its kink at t = 0 is a node).
  const double s = std::sqrt(2.0) * sigma_px;
  const auto integrand = [&](double t) { return (1.0 - std::abs(t)) * normal_pdf(lag - t, s); };
  double total = 0;
  for (const double start : {-1.0, 0.0}) {
    const double h = 1.0 / kSimpsonIntervals;
    double sum = integrand(start) + integrand(start + 1.0);
    for (int k = 1; k < kSimpsonIntervals; ++k) sum += (k % 2 == 1 ? 4.0 : 2.0) * integrand(start + k * h);
    total += sum * h / 3.0;
  }
  return total;
}

double sigma_from_lag_ratio(double ratio) {
  const auto& table = lag_ratio_table().ratio;
  if (!std::isfinite(ratio) || ratio > table.front() || ratio < table.back()) return kNaN;
  // First entry at or below `ratio` (the table decreases), then linear in log sigma.
  const auto it = std::lower_bound(table.begin(), table.end(), ratio, std::greater<double>());
  const auto n = static_cast<int>(it - table.begin());
  if (n == 0) return table_sigma(0);
  const double r0 = table[static_cast<std::size_t>(n - 1)], r1 = table[static_cast<std::size_t>(n)];
  const double f = r0 > r1 ? (r0 - ratio) / (r0 - r1) : 0.0;
  return std::exp(std::log(table_sigma(n - 1)) + f * (std::log(table_sigma(n)) - std::log(table_sigma(n - 1))));
}

double density_from_autocovariance(double excess, double lag1_covariance, double sigma_px) {
  if (!(excess > 0 && lag1_covariance > 0 && std::isfinite(sigma_px))) return kNaN;
  return excess * excess * pixel_autocorrelation(0.0, sigma_px) * pixel_autocorrelation(1.0, sigma_px) /
         lag1_covariance;
}

}  // namespace tomorig::quicklook::detail
