#include "tomorig/processing/particles/sparsify.h"

#include <omp.h>

#include <cstdint>
#include <limits>
#include <vector>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::particles {

SparseVolume sparsify(const DenseVolume& dense, float floor, int threads) {
  const VoxelGrid& g = dense.grid;
  if (g.voxel_count() > std::numeric_limits<std::uint32_t>::max())
    throw bad_input(fmt::format("sparsify: grid of {} voxels exceeds the 2^32 a sparse volume can index",
                                g.voxel_count()));
  if (dense.values.size() != g.voxel_count())
    throw bad_input(fmt::format("sparsify: dense volume holds {} values but its {} x {} x {} grid needs {}",
                                dense.values.size(), g.nx, g.ny, g.nz, g.voxel_count()));
  const std::size_t slice = static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny);
  const int nz = g.nz;
  const int used = threads > 0 ? threads : omp_get_max_threads();
  // Two passes per slice (count, then copy to the slice's offset): no reallocation, and the
  // output order is the index order whatever the thread count.
  std::vector<std::size_t> start(static_cast<std::size_t>(nz) + 1, 0);
#pragma omp parallel for schedule(static) num_threads(used)
  for (int k = 0; k < nz; ++k) {
    const float* v = dense.values.data() + slice * k;
    std::size_t count = 0;
    for (std::size_t n = 0; n < slice; ++n) count += v[n] > floor ? 1 : 0;
    start[k + 1] = count;
  }
  for (int k = 0; k < nz; ++k) start[k + 1] += start[k];
  SparseVolume sparse;
  sparse.grid = g;
  sparse.index.resize(start[nz]);
  sparse.intensity.resize(start[nz]);
#pragma omp parallel for schedule(static) num_threads(used)
  for (int k = 0; k < nz; ++k) {
    const float* v = dense.values.data() + slice * k;
    std::size_t out = start[k];
    const std::uint32_t base = static_cast<std::uint32_t>(slice * k);
    for (std::size_t n = 0; n < slice; ++n)
      if (v[n] > floor) {
        sparse.index[out] = base + static_cast<std::uint32_t>(n);
        sparse.intensity[out] = v[n];
        ++out;
      }
  }
  return sparse;
}

}  // namespace tomorig::particles
