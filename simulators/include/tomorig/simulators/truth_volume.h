#pragma once
// The ground-truth volume of a simulation (thesis Sect. 3.2.2): a 3-D Gaussian of diameter
// 4 sigma = 3 voxel at every true particle position, on the reconstruction grid. This is the
// "G" of the quality factor Q (Eq. 3.14) and the reference of the "noise-free" correlation.
//
// The rendering itself lives in processing/quality (gaussian_blobs.h), because the quality
// metrics rebuild the same volume from a particle list; this header is the simulator's name
// for it, next to the other ground truth the simulator produces.
#include <span>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"
#include "tomorig/processing/quality/gaussian_blobs.h"

namespace tomorig::sim {

// sigma_voxel (0.75), peak (1.0), cutoff_sigmas (3.5: only voxels within 3.5 sigma per axis
// are stored) and threads.
using TruthVolumeOptions = quality::GaussianBlobOptions;

// Sparse: only the voxels the blobs touch (ascending indices); overlapping blobs add.
// `particles_mm`: world positions (mm). Throws tomorig::Error (bad_input) on a bad grid,
// bad options or a non-finite position. Deterministic whatever the thread count.
SparseVolume truth_volume(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                          const TruthVolumeOptions& options = {});

// The same as a dense volume (every voxel stored; 168 MB for 512 x 512 x 160).
DenseVolume truth_volume_dense(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                               const TruthVolumeOptions& options = {});

}  // namespace tomorig::sim
