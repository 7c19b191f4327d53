#include "correlation/volume_view.h"

#include <algorithm>
#include <cmath>

namespace tomorig::piv::detail {

float largest_magnitude(const VolumeView& v, int threads) {
  float largest = 0.0f;
  const long long count = static_cast<long long>(v.count());
#pragma omp parallel for num_threads(threads) reduction(max : largest) schedule(static)
  for (long long n = 0; n < count; ++n) largest = std::max(largest, std::abs(v.data[n]));
  return largest;
}

}  // namespace tomorig::piv::detail
