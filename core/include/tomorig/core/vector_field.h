#pragma once
// A 3-D grid of displacement vectors (3-D3C), one per interrogation volume centre.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig {

enum class VectorStatus : std::uint8_t {
  valid = 0,     // measured and passed validation
  replaced = 1,  // failed validation, replaced by an interpolated value
  invalid = 2,   // failed validation and could not be replaced, or masked out
};

struct VectorField {
  int nx = 0, ny = 0, nz = 0;
  Vec3d origin;        // world position (mm) of vector (0, 0, 0)
  Vec3d spacing;       // mm between neighbouring vectors along x, y, z
  std::vector<Vec3f> displacement;     // voxels, x fastest
  std::vector<VectorStatus> status;
  std::vector<float> peak;             // correlation coefficient of the chosen peak

  VectorField() = default;
  VectorField(int nx_, int ny_, int nz_)
      : nx(nx_), ny(ny_), nz(nz_), displacement(count()), status(count(), VectorStatus::invalid), peak(count(), 0.0f) {}
  std::size_t count() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  }
  std::size_t linear(int i, int j, int k) const {
    return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(k));
  }
};

}  // namespace tomorig
