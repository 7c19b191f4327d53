#pragma once
// Intensity versus depth (thesis Fig. 3.10 and 5.9) and the reconstruction signal-to-noise
// ratio (RSNR, Sect. 3.2.2 and 3.3.2): "the spatially averaged intensity level outside the
// particle volume border is evaluated against the signal strength inside the particle
// volume". Here:
//   profile[k]  = mean intensity per voxel of z-slice k (optionally without a lateral border;
//                 the thesis averaged 400 x 400 of 512 x 512 voxels),
//   signal      = mean of profile[k] over slices whose centre lies inside the seeded slab,
//   noise       = mean of profile[k] over slices more than `noise_margin_voxel` outside it,
//   RSNR        = signal / noise.
// The margin keeps the tails of particles sitting on the slab border out of the noise level.
#include <cstddef>
#include <vector>

#include "tomorig/core/volume.h"
#include "tomorig/processing/quality/ellipsoid_mask.h"

namespace tomorig::quality {

struct DepthProfile {
  // Per z-slice mean intensity per voxel (over the slice area without the lateral margin).
  std::vector<double> total;         // whole reconstruction
  std::vector<double> true_part;     // voxels inside the true-particle mask
  std::vector<double> ghost_part;    // voxels outside it (total = true_part + ghost_part)
  std::vector<double> truth;         // the ground-truth volume, for reference (empty if not given)
  int lateral_margin_voxel = 0;
};

// Profiles of `volume` (and of `truth`, if non-null) split by `mask`. The margin is clipped
// so at least one column remains. The grids must match (bad_input otherwise).
DepthProfile depth_profile(const SparseVolume& volume, const EllipsoidMask& mask, const SparseVolume* truth,
                           int lateral_margin_voxel = 0);

struct SignalToNoise {
  double signal = 0.0;          // mean profile level inside the slab
  double noise = 0.0;           // mean profile level outside it (beyond the margin)
  double ratio = 0.0;           // signal / noise; +inf if noise is 0; NaN if no slice qualifies
  std::size_t signal_slices = 0, noise_slices = 0;
};

// RSNR from `profile` (one value per slice k, slice centre at k) and the seeded slab
// [slab_min_voxel, slab_max_voxel] in continuous voxel z.
SignalToNoise reconstruction_snr(const std::vector<double>& profile, double slab_min_voxel, double slab_max_voxel,
                                 double noise_margin_voxel = 2.25);

}  // namespace tomorig::quality
