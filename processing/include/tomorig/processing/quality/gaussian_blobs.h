#pragma once
// The ground-truth volume of the quality metrics (thesis Sect. 3.2.2): one 3-D Gaussian per
// true particle, sampled at voxel centres and summed where particles overlap. Diameter
// 4 sigma = 3 voxel by default, the particle image diameter of Table 3.1.
//
// A particle at continuous voxel position (x, y, z) adds to voxel (i, j, k)
//   peak * exp(-((i - x)^2 + (j - y)^2 + (k - z)^2) / (2 sigma^2))
// for every voxel with |i - x|, |j - y|, |k - z| <= cutoff_sigmas * sigma (a box, so the
// weights are separable). At sigma = 0.75 voxel, point sampling reproduces the continuous
// integral peak * (2 pi)^(3/2) sigma^3 and the centroid to better than 1e-4.
#include <span>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::quality {

struct GaussianBlobOptions {
  double sigma_voxel = 0.75;    // 4 sigma = 3 voxel (thesis Sect. 3.2.2); change for other PSFs
  double peak = 1.0;            // value at the centre of an isolated blob
  // Half-width of the box rendered around each particle, in sigma. 3.5 sigma keeps the lost
  // mass below 1 % (per axis < 0.25 %); 5 sigma below 1e-5, at 2.5x the voxels.
  double cutoff_sigmas = 3.5;
  int threads = 0;              // OpenMP threads; 0: the OpenMP default. Never changes the result.

  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

// The blobs of `particles_mm` (world mm) on `grid`, as a sparse volume holding every voxel a
// blob touches (ascending indices, no duplicates). Parts outside the grid are dropped;
// non-finite positions are rejected. Deterministic whatever the thread count.
SparseVolume gaussian_blob_volume(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                                  const GaussianBlobOptions& options = {});

}  // namespace tomorig::quality
