#include "histogram_stats.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tomorig::quicklook::detail {
namespace {

// One-sided normal tail beyond 1 sigma over the half: P(Z < -1) / P(Z < 0).
constexpr double kOneSigmaOfHalf = 0.158655253931457 / 0.5;

// log(n) of the counts a tile's histogram holds (std::log's own values, looked up: the fit
// below takes one per bin, for every tile of every frame); larger counts call std::log.
constexpr std::size_t kLogTableSize = 4096;
struct LogTable {
  double value[kLogTableSize];
  LogTable() {
    value[0] = -std::numeric_limits<double>::infinity();
    for (std::size_t n = 1; n < kLogTableSize; ++n) value[n] = std::log(static_cast<double>(n));
  }
};
double log_count(std::uint32_t n) {
  static const LogTable table;  // built once, thread-safe
  return n < kLogTableSize ? table.value[n] : std::log(static_cast<double>(n));
}

}  // namespace

double quantile(std::span<const std::uint32_t> histogram, double total, double p) {
  const double target = std::clamp(p, 0.0, 1.0) * total;
  double cumulative = 0;
  for (std::size_t v = 0; v < histogram.size(); ++v) {
    cumulative += histogram[v];
    if (cumulative >= target && histogram[v] > 0) return static_cast<double>(v);
  }
  return static_cast<double>(histogram.size() - 1);
}

double quantile_continuous(std::span<const std::uint32_t> histogram, double total, double p) {
  const double target = std::clamp(p, 0.0, 1.0) * total;
  double before = 0;
  for (std::size_t v = 0; v < histogram.size(); ++v) {
    const double h = histogram[v];
    if (h > 0 && before + h >= target) return static_cast<double>(v) - 0.5 + (target - before) / h;
    before += h;
  }
  return static_cast<double>(histogram.size()) - 0.5;
}

double cumulative_continuous(std::span<const std::uint32_t> histogram, double value) {
  double below = 0;
  for (std::size_t v = 0; v < histogram.size(); ++v) {
    const double lo = static_cast<double>(v) - 0.5;
    if (value <= lo) break;
    below += histogram[v] * std::min(1.0, value - lo);
  }
  return below;
}

double half_sample_mode(std::span<const std::uint32_t> histogram) {
  std::size_t lo = 0, hi = histogram.size();
  while (lo < hi && histogram[lo] == 0) ++lo;
  while (hi > lo && histogram[hi - 1] == 0) --hi;
  if (lo >= hi) return 0.0;
  --hi;  // inclusive from here on
  // Each pass keeps a strictly narrower run (a run of half the pixels always exists that is
  // shorter than the whole), so this ends; the bound only guards against a mistake.
  // Counts in integers: exact, and one-cycle adds in the two-pointer loop.
  std::uint64_t mass = 0;  // in [lo, hi]
  for (std::size_t v = lo; v <= hi; ++v) mass += histogram[v];
  for (int pass = 0; pass < 64 && hi - lo + 1 > 3; ++pass) {
    const std::uint64_t half = (mass + 1) / 2;
    // Narrowest [a, b] with at least `half` pixels (two pointers over the bins); of equally
    // narrow runs the fullest, so that integer bins do not pull the mode to one side.
    std::size_t best_a = lo, best_b = hi, b = lo;
    std::uint64_t best_inside = 0, inside = histogram[lo];
    for (std::size_t a = lo; a <= hi; ++a) {
      while (inside < half && b < hi) inside += histogram[++b];
      if (inside < half) break;
      if (b - a < best_b - best_a || (b - a == best_b - best_a && inside > best_inside)) {
        best_a = a;
        best_b = b;
        best_inside = inside;
      }
      inside -= histogram[a];
    }
    if (best_b - best_a >= hi - lo) break;
    lo = best_a;
    hi = best_b;
    mass = best_inside;
  }
  double sum = 0, weighted = 0;
  for (std::size_t v = lo; v <= hi; ++v) {
    sum += histogram[v];
    weighted += static_cast<double>(v) * histogram[v];
  }
  return sum > 0 ? weighted / sum : static_cast<double>(lo);
}

double lower_half_sigma(std::span<const std::uint32_t> histogram, double mode) {
  const double below_mode = cumulative_continuous(histogram, mode);
  if (below_mode <= 0) return 0.0;
  const double one_sigma_below = quantile_continuous(histogram, below_mode, kOneSigmaOfHalf);
  return std::max(0.0, mode - one_sigma_below);
}

double refine_mode(std::span<const std::uint32_t> histogram, double mode, double sigma) {
  if (!(sigma >= 1.5)) return mode;  // too few bins across the peak to fit
  const auto lo = static_cast<std::ptrdiff_t>(std::max(0.0, std::ceil(mode - 2.0 * sigma)));
  const auto hi = std::min(static_cast<std::ptrdiff_t>(histogram.size()) - 1,
                           static_cast<std::ptrdiff_t>(std::floor(mode + 0.5 * sigma)));
  // Weighted least squares of log h = c0 + c1 u + c2 u^2, u = v - mode.
  double m[3][4] = {};
  int used = 0;
  for (std::ptrdiff_t v = lo; v <= hi; ++v) {
    const std::uint32_t count = histogram[static_cast<std::size_t>(v)];
    if (count < 1) continue;
    const double h = count;
    const double u = static_cast<double>(v) - mode, y = log_count(count);
    const double basis[3] = {1.0, u, u * u};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[r][c] += h * basis[r] * basis[c];
      m[r][3] += h * basis[r] * y;
    }
    ++used;
  }
  if (used < 4) return mode;
  // Gaussian elimination with partial pivoting on the 3 x 4 system.
  for (int col = 0; col < 3; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 3; ++r)
      if (std::abs(m[r][col]) > std::abs(m[pivot][col])) pivot = r;
    if (std::abs(m[pivot][col]) < 1e-12) return mode;
    for (int c = 0; c < 4; ++c) std::swap(m[col][c], m[pivot][c]);
    for (int r = 0; r < 3; ++r) {
      if (r == col) continue;
      const double f = m[r][col] / m[col][col];
      for (int c = col; c < 4; ++c) m[r][c] -= f * m[col][c];
    }
  }
  const double c1 = m[1][3] / m[1][1], c2 = m[2][3] / m[2][2];
  if (!(c2 < 0)) return mode;
  const double shift = -c1 / (2 * c2);
  return std::abs(shift) <= sigma ? mode + shift : mode;
}

double floor_clipped_sigma(std::span<const std::uint32_t> histogram, int floor) {
  const double at_floor = histogram[static_cast<std::size_t>(floor)];
  if (at_floor <= 0) return 0.0;
  double below = 0;
  for (int v = 0; v < floor; ++v) below += histogram[static_cast<std::size_t>(v)];
  // Values measured from the floor; the floor bin ends half a count above it.
  const double x = quantile_continuous(histogram, below + 1.5 * at_floor, 1.0) - floor;
  const auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  const auto g = [&](double sigma) { return phi(x / sigma) - 1.5 * phi(0.5 / sigma); };
  // g < 0 at both ends (tiny sigma: the floor would hold nearly everything; huge sigma: it
  // would hold half), > 0 between: the root on the falling side is the background's noise
  // (the other makes the floor hold more than two thirds of it). Bracket it on a log grid.
  if (!(x > 0.5)) return 0.0;
  double lo = 0, hi = 0;
  constexpr int kGrid = 400;
  const double first = 0.05, last = 1e4 * x;
  for (int k = kGrid; k > 0; --k) {
    const double a = first * std::pow(last / first, static_cast<double>(k - 1) / kGrid);
    const double b = first * std::pow(last / first, static_cast<double>(k) / kGrid);
    if (g(a) > 0 && g(b) <= 0) {
      lo = a;
      hi = b;
      break;
    }
  }
  if (lo <= 0) return 0.0;
  for (int it = 0; it < 60; ++it) {
    const double mid = std::sqrt(lo * hi);
    (g(mid) > 0 ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

}  // namespace tomorig::quicklook::detail
