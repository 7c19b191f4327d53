#include "particles/volume_checks.h"

#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::particles::detail {

void check_grid(const VoxelGrid& grid, const std::string& what) {
  if (grid.nx <= 0 || grid.ny <= 0 || grid.nz <= 0)
    throw bad_input(fmt::format("{}: grid is {} x {} x {} voxels; every dimension must be > 0", what, grid.nx,
                                grid.ny, grid.nz));
  if (!(grid.voxel_size > 0.0) || !std::isfinite(grid.voxel_size))
    throw bad_input(fmt::format("{}: grid voxel_size = {} mm; it must be a finite value > 0", what, grid.voxel_size));
  if (!std::isfinite(grid.origin.x) || !std::isfinite(grid.origin.y) || !std::isfinite(grid.origin.z))
    throw bad_input(fmt::format("{}: grid origin is not finite", what));
  if (grid.voxel_count() > std::numeric_limits<std::uint32_t>::max())
    throw bad_input(fmt::format("{}: grid of {} voxels exceeds the 2^32 voxels a sparse volume can index; "
                                "split it into sub-volumes",
                                what, grid.voxel_count()));
}

void check_sparse(const SparseVolume& volume, const std::string& what) {
  check_grid(volume.grid, what);
  if (volume.index.size() != volume.intensity.size())
    throw bad_input(fmt::format("{}: sparse volume has {} indices but {} intensities; they must match", what,
                                volume.index.size(), volume.intensity.size()));
  const std::size_t count = volume.grid.voxel_count();
  for (std::size_t n = 0; n < volume.index.size(); ++n) {
    if (volume.index[n] >= count)
      throw bad_input(fmt::format("{}: sparse entry {} has index {} outside the grid of {} voxels", what, n,
                                  volume.index[n], count));
    if (n > 0 && volume.index[n] <= volume.index[n - 1])
      throw bad_input(fmt::format("{}: sparse indices must ascend strictly; entry {} ({}) follows {}", what, n,
                                  volume.index[n], volume.index[n - 1]));
  }
}

void check_same_grid(const VoxelGrid& a, const VoxelGrid& b, const std::string& what_a, const std::string& what_b) {
  const bool same = a.nx == b.nx && a.ny == b.ny && a.nz == b.nz && a.voxel_size == b.voxel_size &&
                    a.origin.x == b.origin.x && a.origin.y == b.origin.y && a.origin.z == b.origin.z;
  if (!same)
    throw bad_input(fmt::format("{} is on a {} x {} x {} grid (voxel {} mm) but {} on {} x {} x {} (voxel {} mm); "
                                "both must use the same grid",
                                what_a, a.nx, a.ny, a.nz, a.voxel_size, what_b, b.nx, b.ny, b.nz, b.voxel_size));
}

}  // namespace tomorig::particles::detail
