#include "support.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "mlos.h"
#include "sparse_system.h"
#include "stage_timer.h"
#include "system_memory.h"

namespace tomorig::recon::detail {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Support build_support(const ReconstructionInput& input, const ReconstructionOptions& options, const SupportNeeds& needs,
                      ReconstructionReport& report, MlosBuffers* buffers) {
  const auto start = std::chrono::steady_clock::now();
  StageTimer timer("support");
  Support s;
  s.in = prepare_input(input, options);
  timer.mark("prepare_input");
  report.threads = s.in.threads;
  double sigma = 0;
  for (const PsfModel& psf : s.in.psf) sigma = std::max(sigma, psf.max_sigma());
  // p = ceil(4 sigma) (Sect. 3.1.3), rounded up to odd so that the patch is centred on the
  // voxel's image, and at least 3.
  int p = std::max(3, static_cast<int>(std::ceil(4.0 * sigma - 1e-9)));
  if (p % 2 == 0) ++p;
  s.patch = options.patch_size > 0 ? options.patch_size : p;

  // Up front: the images and their copies, plus an upper bound on the support. An active voxel
  // must be non-empty in every camera, so in particular in the most selective one: the support
  // is at most the fraction of that camera's pixels whose bilinear neighbourhood holds a pixel
  // above the threshold. MLOS re-checks with the real count as the support grows.
  const double per_voxel = needs.positions
                               ? SparseSystem::estimate_bytes(s.in, 1, s.patch, 0) -
                                     SparseSystem::estimate_bytes(s.in, 0, s.patch, 0) + needs.extra_bytes_per_voxel
                               : 8.0 + needs.extra_bytes_per_voxel;
  const double fixed = needs.positions ? SparseSystem::estimate_bytes(s.in, 0, s.patch, s.in.threads)
                                       : image_bytes(s.in, 2, 1);
  double expected_fraction = 1.0;
  for (const CameraImage& im : s.in.images) {
    const float cut = static_cast<float>(needs.mlos_threshold) * im.max;
    auto lit = [&](int x, int y) {
      if (x < 0 || y < 0 || x >= im.width || y >= im.height) return false;
      const float v = im.at(x, y);
      return v > 0 && v >= cut;
    };
    std::size_t reachable = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        reachable += lit(x, y) || lit(x - 1, y) || lit(x, y - 1) || lit(x - 1, y - 1);
    expected_fraction = std::min(expected_fraction, static_cast<double>(reachable) / static_cast<double>(im.pixels.size()));
  }
  const double estimate = fixed + per_voxel * expected_fraction * static_cast<double>(s.in.grid.voxel_count());
  report.estimated_memory_mb = estimate / (1024.0 * 1024.0);
  require_memory(estimate, options.memory_limit_mb,
                 fmt::format("a grid of {} x {} x {} voxels (up to {:.1f} % of them active)", s.in.grid.nx, s.in.grid.ny,
                             s.in.grid.nz, 100.0 * expected_fraction));

  timer.mark("memory estimate");
  const GridProjector& projector = s.projector.emplace(s.in);
  timer.mark("grid projector");
  MlosSettings mlos;
  mlos.threshold = needs.mlos_threshold;
  mlos.fixed_bytes = fixed;
  mlos.bytes_per_voxel = per_voxel;
  mlos.memory_limit_mb = options.memory_limit_mb;
  mlos.buffers = buffers;
  s.set = run_mlos(s.in, projector, mlos);
  timer.mark("mlos");
  report.active_voxels = s.set.size();
  report.estimated_memory_mb = (fixed + per_voxel * static_cast<double>(s.set.size())) / (1024.0 * 1024.0);
  report.setup_seconds = seconds_since(start);
  return s;
}

SparseVolume to_volume(const VoxelGrid& grid, const std::vector<std::uint32_t>& index, const std::vector<float>& e) {
  SparseVolume v;
  v.grid = grid;
  std::size_t nonzero = 0;
  for (float x : e) nonzero += x > 0.0f;
  v.index.reserve(nonzero);
  v.intensity.reserve(nonzero);
  for (std::size_t n = 0; n < e.size(); ++n)
    if (e[n] > 0.0f) {
      v.index.push_back(index[n]);
      v.intensity.push_back(e[n]);
    }
  return v;
}

bool record_iteration(ReconstructionReport& report, int iteration, double residual, double mean_update,
                      double seconds, double stop_mean_update) {
  IterationStats stats;
  stats.iteration = iteration;
  stats.residual = residual;
  stats.mean_update = mean_update;
  stats.seconds = seconds;
  report.history.push_back(stats);
  report.iterations = iteration;
  return stop_mean_update > 0 && mean_update < stop_mean_update;
}

}  // namespace tomorig::recon::detail
