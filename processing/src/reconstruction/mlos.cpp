#include "mlos.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cmath>
#include <exception>
#include <numeric>
#include <string>

#include <fmt/core.h>

#include "stage_timer.h"
#include "support_scan.h"
#include "system_memory.h"
#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
ActiveSet run_mlos(const PreparedInput& in, const GridProjector& projector, const MlosSettings& settings) {
  const VoxelGrid& g = in.grid;
  // Thresholded images, reach masks, cameras ordered most selective first (support_scan.h).
  const SupportScanner scanner(in, projector, settings.threshold);

  const double limit_mb = settings.memory_limit_mb > 0 ? settings.memory_limit_mb : usable_memory_mb();
  const double budget_voxels =
      limit_mb > 0 && settings.bytes_per_voxel > 0
          ? (limit_mb * 1024.0 * 1024.0 - settings.fixed_bytes) / settings.bytes_per_voxel
          : 1e300;
  std::atomic<std::size_t> active{0};
  std::atomic<bool> over_budget{false};

  MlosBuffers own;
  MlosBuffers& buffers = settings.buffers ? *settings.buffers : own;
  std::vector<MlosBuffers::Slice>& slices = buffers.slices;
  slices.resize(static_cast<std::size_t>(g.nz));
  for (MlosBuffers::Slice& s : slices) {  // emptied, their capacity (and its touched pages) kept
    s.index.clear();
    s.value.clear();
  }
  // Blocks of kSlabSlices z-slices, row by row across the block: the same grid row j of
  // neighbouring slices projects to the same few image rows, so their reads hit the cache.
  const int blocks = (g.nz + kSlabSlices - 1) / kSlabSlices;
#pragma omp parallel num_threads(in.threads)
  {
    SupportScanner::Row row = scanner.make_row();
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < blocks; ++b) {
      if (over_budget.load(std::memory_order_relaxed)) continue;
      const int k0 = b * kSlabSlices, k1 = std::min(g.nz, k0 + kSlabSlices);
      std::size_t found = 0;
      for (int j = 0; j < g.ny; ++j)
        for (int k = k0; k < k1; ++k) {
          MlosBuffers::Slice& out = slices[static_cast<std::size_t>(k)];
          const int count = scanner.scan(j, k, row);
          const std::uint32_t base = static_cast<std::uint32_t>(g.linear(0, j, k));
          for (int n = 0; n < count; ++n) {
            const int i = row.alive[static_cast<std::size_t>(n)];
            out.index.push_back(base + static_cast<std::uint32_t>(i));
            out.value.push_back(row.product[static_cast<std::size_t>(i)]);
          }
          found += static_cast<std::size_t>(count);
        }
      const std::size_t total = active.fetch_add(found) + found;
      if (static_cast<double>(total) > budget_voxels) over_budget.store(true);
    }
    if (profiling_enabled()) {
#pragma omp critical
      {
        std::fprintf(stderr, "[profile] mlos thread: voxels tested per camera");
        for (std::size_t o = 0; o < row.tested.size(); ++o)
          std::fprintf(stderr, " %zu: %llu (reach %.3f),", scanner.order()[o],
                       static_cast<unsigned long long>(row.tested[o]), scanner.image(scanner.order()[o]).reach_fraction);
        std::fprintf(stderr, " reachable in all: %llu\n", static_cast<unsigned long long>(row.reached));
      }
    }
  }
  if (over_budget.load()) {
    const std::string what = fmt::format("the MLOS support (at least {} active voxels)", active.load());
    const double bytes = settings.fixed_bytes + settings.bytes_per_voxel * static_cast<double>(active.load());
    require_memory(bytes, limit_mb, what);
    throw bad_input(fmt::format("reconstruction: {} needs more than the {:.0f} MB available", what, limit_mb));
  }

  // Slices concatenated in z order; each slice copies into its own range, in parallel.
  ActiveSet set = std::move(buffers.spare);
  buffers.spare = {};
  std::vector<std::size_t> first(slices.size() + 1, 0);
  for (std::size_t k = 0; k < slices.size(); ++k) first[k + 1] = first[k] + slices[k].index.size();
  const std::size_t total = first.back();
  set.index.resize(total);
  set.value.resize(total);
#pragma omp parallel for num_threads(in.threads) schedule(dynamic, 4)
  for (int k = 0; k < g.nz; ++k) {
    MlosBuffers::Slice& s = slices[static_cast<std::size_t>(k)];
    const std::size_t at = first[static_cast<std::size_t>(k)];
    std::copy(s.index.begin(), s.index.end(), set.index.begin() + at);
    std::copy(s.value.begin(), s.value.end(), set.value.begin() + at);
    if (!settings.buffers) s = {};  // nobody keeps them: free early
  }
  return set;
}

}  // namespace tomorig::recon::detail
