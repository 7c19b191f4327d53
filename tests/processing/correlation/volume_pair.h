#pragma once
// Volume pairs of known displacement for the correlation tests: random particles at mid-time
// positions X, rendered as 3-D Gaussians (diameter 3 voxel) at X - d(X)/2 in volume a and
// X + d(X)/2 in volume b, the convention of the tpiv-thesis case.
#include <functional>
#include <random>
#include <vector>

#include "tomorig/core/volume.h"
#include "tomorig/processing/quality/gaussian_blobs.h"

namespace corr_test {

using tomorig::Vec3d;

struct VolumePair {
  tomorig::DenseVolume a, b;
};

inline tomorig::VoxelGrid test_grid(int nx, int ny, int nz) { return tomorig::VoxelGrid::centred(nx, ny, nz, 0.02); }

// `per_voxel` particles per voxel, uniformly over the grid plus a margin so that particles
// moving in through the boundary exist; `displacement` maps a voxel position to voxels.
inline VolumePair make_pair(const tomorig::VoxelGrid& grid, double per_voxel,
                            const std::function<Vec3d(const Vec3d&)>& displacement, unsigned seed = 7) {
  std::mt19937 rng(seed);
  const double margin = 8.0;
  std::uniform_real_distribution<double> ux(-margin, grid.nx - 1 + margin), uy(-margin, grid.ny - 1 + margin),
      uz(-margin, grid.nz - 1 + margin);
  const auto count = static_cast<std::size_t>(per_voxel * (grid.nx + 2 * margin) * (grid.ny + 2 * margin) *
                                              (grid.nz + 2 * margin));
  std::vector<Vec3d> pa, pb;
  for (std::size_t n = 0; n < count; ++n) {
    const Vec3d x{ux(rng), uy(rng), uz(rng)};
    const Vec3d d = displacement(x);
    const Vec3d xa = x - d * 0.5, xb = x + d * 0.5;
    pa.push_back(grid.centre_of(xa.x, xa.y, xa.z));
    pb.push_back(grid.centre_of(xb.x, xb.y, xb.z));
  }
  return {tomorig::quality::gaussian_blob_volume(grid, pa).to_dense(),
          tomorig::quality::gaussian_blob_volume(grid, pb).to_dense()};
}

}  // namespace corr_test
