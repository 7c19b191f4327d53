#include "tomorig/simulators/truth_volume.h"

namespace tomorig::sim {

SparseVolume truth_volume(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                          const TruthVolumeOptions& options) {
  return quality::gaussian_blob_volume(grid, particles_mm, options);
}

DenseVolume truth_volume_dense(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                               const TruthVolumeOptions& options) {
  return quality::gaussian_blob_volume(grid, particles_mm, options).to_dense();
}

}  // namespace tomorig::sim
