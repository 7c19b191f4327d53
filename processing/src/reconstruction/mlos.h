#pragma once
// Multiplicative line of sight (MLOS; thesis Sect. 3.1.3 after Atkinson and Soria): a single
// dense pass over the grid in which a voxel's intensity is the product over cameras of the
// bilinearly interpolated (normalised) pixel intensity at its image position. A voxel that is
// empty in any camera (below the threshold) is inactive; the active voxels are the sparse
// support of SMART and FMART. The volume is never held dense: z-slices are processed in
// parallel and only active voxels are kept.
#include "active_set.h"
#include "grid_projector.h"
#include "prepared_input.h"
#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon::detail {

struct MlosSettings {
  // Fraction of each image's maximum below which a pixel is empty (default: the one in
  // ReconstructionOptions).
  double threshold = ReconstructionOptions{}.mlos_threshold;
  // Memory check while the support grows: refuse once fixed + per_voxel * active exceeds it.
  double fixed_bytes = 0.0;
  double bytes_per_voxel = 0.0;
  double memory_limit_mb = 0.0;  // 0: MemAvailable
};

// Throws tomorig::Error (bad_input) if the support outgrows the memory limit.
ActiveSet run_mlos(const PreparedInput& in, const GridProjector& projector, const MlosSettings& settings);

}  // namespace tomorig::recon::detail
