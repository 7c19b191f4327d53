#include "tomorig/processing/correlation/vector_validation.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace tomorig::piv {
namespace {

// Median of the first n values (partially reorders them).
float median_of(float* values, int n) {
  const int half = n / 2;
  std::nth_element(values, values + half, values + n);
  const float upper = values[half];
  if (n % 2 == 1) return upper;
  const float lower = *std::max_element(values, values + half);
  return 0.5f * (lower + upper);
}

struct Neighbourhood {
  std::array<std::array<float, 26>, 3> components;
  int count = 0;
};

// The measured neighbours (3x3x3 block without the centre) of node (i, j, k).
Neighbourhood gather(const VectorField& field, const std::vector<std::uint8_t>& measured, int i, int j, int k) {
  Neighbourhood hood;
  for (int dk = -1; dk <= 1; ++dk)
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        if (di == 0 && dj == 0 && dk == 0) continue;
        const int x = i + di, y = j + dj, z = k + dk;
        if (x < 0 || y < 0 || z < 0 || x >= field.nx || y >= field.ny || z >= field.nz) continue;
        const std::size_t n = field.linear(x, y, z);
        if (!measured[n]) continue;
        hood.components[0][hood.count] = field.displacement[n].x;
        hood.components[1][hood.count] = field.displacement[n].y;
        hood.components[2][hood.count] = field.displacement[n].z;
        ++hood.count;
      }
  return hood;
}

float component(const Vec3f& v, int c) { return c == 0 ? v.x : (c == 1 ? v.y : v.z); }

}  // namespace

ValidationCounts validate_field(VectorField& field, const CorrelationOptions& options,
                                const std::vector<std::uint8_t>& mask) {
  ValidationCounts counts;
  const std::size_t count = field.count();
  // Measured: a vector the tests below may use as a neighbour. Outliers: to be replaced.
  std::vector<std::uint8_t> measured(count, 0), outlier(count, 0);
  for (std::size_t n = 0; n < count; ++n) {
    if (!mask.empty() && !mask[n]) {
      field.status[n] = VectorStatus::invalid;
      ++counts.masked;
      continue;
    }
    if (field.status[n] == VectorStatus::invalid) continue;
    if (options.min_peak > 0.0 && !(field.peak[n] >= options.min_peak)) {
      field.status[n] = VectorStatus::invalid;
      ++counts.low_peak;
      continue;
    }
    const Vec3f& d = field.displacement[n];
    if (options.max_displacement > 0.0 &&
        std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z) > options.max_displacement) {
      outlier[n] = 1;
      ++counts.too_large;
      continue;
    }
    measured[n] = 1;
  }
  if (options.median_test.enabled) {
    std::vector<std::uint8_t> fails(count, 0);
    // Each node is judged against the measured flags alone and writes only its own flag, so
    // the planes can be judged in parallel with the same outcome.
    const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int k = 0; k < field.nz; ++k)
      for (int j = 0; j < field.ny; ++j)
        for (int i = 0; i < field.nx; ++i) {
          const std::size_t n = field.linear(i, j, k);
          if (!measured[n]) continue;
          Neighbourhood hood = gather(field, measured, i, j, k);
          if (hood.count < 2) continue;  // too few neighbours to judge
          for (int c = 0; c < 3; ++c) {
            float* values = hood.components[c].data();
            const float median = median_of(values, hood.count);
            // The residuals' median only raises the denominator above epsilon: a component
            // within threshold * epsilon of the median passes whatever it is (the same
            // decision, most components of a good field, without the second median).
            const double deviation = std::fabs(component(field.displacement[n], c) - median);
            if (deviation / options.median_test.epsilon <= options.median_test.threshold) continue;
            std::array<float, 26> residuals{};
            for (int m = 0; m < hood.count; ++m) residuals[m] = std::fabs(values[m] - median);
            const float residual_median = median_of(residuals.data(), hood.count);
            const double normalised = deviation / (residual_median + options.median_test.epsilon);
            if (normalised > options.median_test.threshold) {
              fails[n] = 1;
              break;
            }
          }
        }
    // Judge all vectors against the same neighbours first, then remove the failures, so the
    // outcome does not depend on the visiting order.
    for (std::size_t n = 0; n < count; ++n)
      if (fails[n]) {
        measured[n] = 0;
        outlier[n] = 1;
        ++counts.median_outliers;
      }
  }
  std::vector<Vec3f> replacement(count);
  for (int k = 0; k < field.nz; ++k)
    for (int j = 0; j < field.ny; ++j)
      for (int i = 0; i < field.nx; ++i) {
        const std::size_t n = field.linear(i, j, k);
        if (!outlier[n]) continue;
        Neighbourhood hood = gather(field, measured, i, j, k);
        if (hood.count == 0) {
          field.status[n] = VectorStatus::invalid;
          continue;
        }
        replacement[n] = {median_of(hood.components[0].data(), hood.count),
                          median_of(hood.components[1].data(), hood.count),
                          median_of(hood.components[2].data(), hood.count)};
        field.status[n] = VectorStatus::replaced;
        ++counts.replaced;
      }
  for (std::size_t n = 0; n < count; ++n)
    if (outlier[n] && field.status[n] == VectorStatus::replaced) field.displacement[n] = replacement[n];
  return counts;
}

}  // namespace tomorig::piv
