#include "correlation/window_kernels.h"

#include <algorithm>
#include <limits>

namespace tomorig::piv::detail {

#define TOMORIG_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]

TOMORIG_CLONES void spectrum_product(float* fa, const float* fb, std::size_t count) {
#pragma omp simd
  for (std::size_t m = 0; m < count; ++m) {
    const float ar = fa[2 * m], ai = fa[2 * m + 1], br = fb[2 * m], bi = fb[2 * m + 1];
    fa[2 * m] = ar * br + ai * bi;
    fa[2 * m + 1] = ar * bi - ai * br;
  }
}

TOMORIG_CLONES std::size_t first_maximum(const float* p, std::size_t n) {
  // The maximum in 16 independent lanes (a single running maximum is a latency chain of one
  // comparison per value), then the first block holding it.
  constexpr std::size_t kLanes = 16;
  float lane[kLanes];
  std::fill(lane, lane + kLanes, -std::numeric_limits<float>::infinity());
  const std::size_t blocks = n / kLanes;
  for (std::size_t b = 0; b < blocks; ++b) {
    const float* q = p + b * kLanes;
    for (std::size_t l = 0; l < kLanes; ++l) lane[l] = q[l] > lane[l] ? q[l] : lane[l];
  }
  float best = -std::numeric_limits<float>::infinity();
  for (std::size_t l = 0; l < kLanes; ++l) best = lane[l] > best ? lane[l] : best;
  for (std::size_t m = blocks * kLanes; m < n; ++m) best = p[m] > best ? p[m] : best;
  for (std::size_t b = 0; b < blocks; ++b) {
    const float* q = p + b * kLanes;
    int hit = 0;
    for (std::size_t l = 0; l < kLanes; ++l) hit |= q[l] == best;
    if (hit)
      for (std::size_t l = 0; l < kLanes; ++l)
        if (q[l] == best) return b * kLanes + l;
  }
  for (std::size_t m = blocks * kLanes; m < n; ++m)
    if (p[m] == best) return m;
  return n;  // all NaN (or -inf)
}

}  // namespace tomorig::piv::detail
