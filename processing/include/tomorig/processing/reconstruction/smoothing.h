#pragma once
// Gaussian smoothing of a reconstructed volume. FMART sharpens particles into spikes after a
// few iterations; the thesis smooths every FMART volume with sigma = 0.68 x 0.68 x 0.1 voxel
// before judging it (Sect. 3.2.2), which "maximizes the degree of correlation between the
// reconstruction and the ground truth". tomorig offers the same step, separately, so that a
// result can be reported both ways.
#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::recon {

// The thesis's FMART post-smoothing, in voxels (x, y, z).
inline constexpr Vec3d kThesisFmartSmoothingVoxel{0.68, 0.68, 0.1};

// Separable Gaussian smoothing with per-axis sigma in voxels (0 on an axis: no smoothing
// along it; kernels reach 3 sigma, and an axis whose kernel would not reach the next voxel
// noticeably, sigma < 0.25, is left alone). The result holds every voxel the kernel reaches,
// in ascending order; intensity is conserved except what spreads past the grid faces.
// Throws tomorig::Error (bad_input) for a negative or non-finite sigma or a malformed volume.
SparseVolume gaussian_smooth(const SparseVolume& volume, const Vec3d& sigma_voxel, int threads = 0);

}  // namespace tomorig::recon
