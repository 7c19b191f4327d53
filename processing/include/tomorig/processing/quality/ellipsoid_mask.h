#pragma once
// The binary mask of "true" voxels (thesis Sect. 3.2.2): the union of axis-aligned
// ellipsoids around the true particle positions, 3 x 3 x 4.5 voxel in diameter by default
// (longer in z because the oblique views elongate reconstructed particles, Eq. 2.11).
// A voxel is inside when its centre satisfies
//   ((i - x) / a)^2 + ((j - y) / b)^2 + ((k - z) / c)^2 <= 1,  (a, b, c) = diameter / 2.
// Stored as one bit per voxel: 5 MiB for the 42-Mvoxel tpiv-thesis grid.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::quality {

class EllipsoidMask {
 public:
  EllipsoidMask() = default;
  // `centres_voxel`: continuous voxel coordinates; parts outside the grid are dropped.
  // Throws tomorig::Error (bad_input) on a bad grid or a diameter that is not > 0.
  EllipsoidMask(const VoxelGrid& grid, std::span<const Vec3d> centres_voxel, const Vec3d& diameter_voxel);

  bool contains(std::uint32_t linear_index) const {
    return (bits_[linear_index >> 6] >> (linear_index & 63)) & 1u;
  }
  std::size_t voxels_inside() const { return inside_; }

 private:
  std::vector<std::uint64_t> bits_;
  std::size_t inside_ = 0;
};

}  // namespace tomorig::quality
