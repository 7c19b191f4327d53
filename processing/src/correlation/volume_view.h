#pragma once
// A read-only view of a dense float volume (x fastest) used inside the correlation module.
#include <cstddef>

namespace tomorig::piv::detail {

struct VolumeView {
  const float* data = nullptr;
  int nx = 0, ny = 0, nz = 0;

  std::size_t linear(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(k));
  }
  std::size_t count() const { return static_cast<std::size_t>(nx) * ny * nz; }
};

// The largest |value| of the volume (0 for an empty one), on `threads` threads.
float largest_magnitude(const VolumeView& v, int threads);

struct Int3 {
  int x = 0, y = 0, z = 0;
};

}  // namespace tomorig::piv::detail
