#pragma once
// The common first half of every reconstructor: check and convert the input, set up the
// projections, check memory up front, run MLOS. And the common last steps: the sparse volume
// and the report's totals.
#include <chrono>
#include <optional>

#include "active_set.h"
#include "grid_projector.h"
#include "mlos.h"
#include "prepared_input.h"
#include "tomorig/processing/reconstruction/reconstructor.h"

namespace tomorig::recon::detail {

struct Support {
  PreparedInput in;
  ActiveSet set;
  std::optional<GridProjector> projector;  // image positions of the voxels, for the sparse system
  int patch = 3;  // p of the sparse system
};

// What the caller will keep per active voxel after MLOS (for the memory checks), and whether
// it needs the voxels' image positions.
struct SupportNeeds {
  double mlos_threshold = ReconstructionOptions{}.mlos_threshold;  // the one default lives there
  bool positions = true;  // a sparse system will be built (for the memory checks)
  double extra_bytes_per_voxel = 0.0;  // beyond the sparse system's own
};

// Throws tomorig::Error (bad_input) as prepare_input, GridProjector and run_mlos do, and if the
// estimated memory exceeds the limit. `buffers` (may be null): MLOS's, kept between runs.
Support build_support(const ReconstructionInput& input, const ReconstructionOptions& options, const SupportNeeds& needs,
                      ReconstructionReport& report, MlosBuffers* buffers = nullptr);

// The voxels of `set` whose intensity is > 0, as a sparse volume.
SparseVolume to_volume(const VoxelGrid& grid, const std::vector<std::uint32_t>& index, const std::vector<float>& e);

// Appends the statistics of one iteration to the report; returns true when the mean update has
// fallen below `stop_mean_update` (if > 0), i.e. when the iterations should stop.
bool record_iteration(ReconstructionReport& report, int iteration, double residual, double mean_update,
                      double seconds, double stop_mean_update);

double seconds_since(std::chrono::steady_clock::time_point start);

}  // namespace tomorig::recon::detail
