#include "tomorig/processing/quality/ellipsoid_mask.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"

namespace tomorig::quality {

EllipsoidMask::EllipsoidMask(const VoxelGrid& grid, std::span<const Vec3d> centres_voxel, const Vec3d& diameter_voxel) {
  particles::detail::check_grid(grid, "ellipsoid mask");
  if (!(diameter_voxel.x > 0 && diameter_voxel.y > 0 && diameter_voxel.z > 0) || !std::isfinite(diameter_voxel.x) ||
      !std::isfinite(diameter_voxel.y) || !std::isfinite(diameter_voxel.z))
    throw bad_input(fmt::format("ellipsoid mask: diameter {} x {} x {} voxel; each must be a finite value > 0",
                                diameter_voxel.x, diameter_voxel.y, diameter_voxel.z));
  bits_.assign((grid.voxel_count() + 63) / 64, 0);
  const Vec3d semi = diameter_voxel * 0.5;
  const Vec3d inv2{1.0 / (semi.x * semi.x), 1.0 / (semi.y * semi.y), 1.0 / (semi.z * semi.z)};
  for (const Vec3d& c : centres_voxel) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)) continue;
    const int i0 = std::max(0, static_cast<int>(std::ceil(c.x - semi.x)));
    const int i1 = std::min(grid.nx - 1, static_cast<int>(std::floor(c.x + semi.x)));
    const int j0 = std::max(0, static_cast<int>(std::ceil(c.y - semi.y)));
    const int j1 = std::min(grid.ny - 1, static_cast<int>(std::floor(c.y + semi.y)));
    const int k0 = std::max(0, static_cast<int>(std::ceil(c.z - semi.z)));
    const int k1 = std::min(grid.nz - 1, static_cast<int>(std::floor(c.z + semi.z)));
    for (int k = k0; k <= k1; ++k) {
      const double dz2 = (k - c.z) * (k - c.z) * inv2.z;
      for (int j = j0; j <= j1; ++j) {
        const double djk = dz2 + (j - c.y) * (j - c.y) * inv2.y;
        if (djk > 1.0) continue;
        for (int i = i0; i <= i1; ++i) {
          if (djk + (i - c.x) * (i - c.x) * inv2.x > 1.0) continue;
          const std::size_t n = grid.linear(i, j, k);
          bits_[n >> 6] |= std::uint64_t{1} << (n & 63);
        }
      }
    }
  }
  for (std::uint64_t word : bits_) inside_ += static_cast<std::size_t>(std::popcount(word));
}

}  // namespace tomorig::quality
