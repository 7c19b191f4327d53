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

// What MLOS allocates per run, kept by a reconstructor between its runs (the exposures and sets
// of a session): the voxels found per z-slice and the arrays of the next active set. On this
// machine the first touch of fresh memory costs more than the scan that fills it
// (docs/performance.md, "Page faults"): the per-slice lists grow in 4 KiB pages, which made
// MLOS the largest source of page faults in `tomorig process`.
struct MlosBuffers {
  struct Slice {
    std::vector<std::uint32_t> index;
    std::vector<float> value;
  };
  std::vector<Slice> slices;
  ActiveSet spare;  // handed back by the caller once done with the last run's active set
};

struct MlosSettings {
  // Fraction of each image's maximum below which a pixel is empty (default: the one in
  // ReconstructionOptions).
  double threshold = ReconstructionOptions{}.mlos_threshold;
  // Memory check while the support grows: refuse once fixed + per_voxel * active exceeds it.
  double fixed_bytes = 0.0;
  double bytes_per_voxel = 0.0;
  double memory_limit_mb = 0.0;  // 0: MemAvailable
  MlosBuffers* buffers = nullptr;  // reused if given; else the run allocates its own
};

// Throws tomorig::Error (bad_input) if the support outgrows the memory limit.
ActiveSet run_mlos(const PreparedInput& in, const GridProjector& projector, const MlosSettings& settings);

}  // namespace tomorig::recon::detail
