#include "tomorig/processing/quality/gaussian_blobs.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

constexpr int kMaxAxisVoxels = 64;  // per-axis box limit: cutoff_sigmas * sigma_voxel <= 31

struct Entry {
  std::uint32_t index;
  float value;
};

// The voxels [first, last] of an axis of `size` voxels within `half` of `centre`; false if none.
bool axis_range(double centre, double half, int size, int& first, int& last) {
  first = std::max(0, static_cast<int>(std::ceil(centre - half)));
  last = std::min(size - 1, static_cast<int>(std::floor(centre + half)));
  return first <= last;
}

struct Box {
  int i0, i1, j0, j1, k0, k1;
};

}  // namespace

void GaussianBlobOptions::validate() const {
  if (!(sigma_voxel > 0.0) || !std::isfinite(sigma_voxel))
    throw bad_input(fmt::format("gaussian blobs: sigma_voxel = {}; it must be a finite value > 0", sigma_voxel));
  if (!(peak > 0.0) || !std::isfinite(peak))
    throw bad_input(fmt::format("gaussian blobs: peak = {}; it must be a finite value > 0", peak));
  if (!(cutoff_sigmas >= 1.0) || cutoff_sigmas * sigma_voxel > (kMaxAxisVoxels / 2 - 1))
    throw bad_input(fmt::format("gaussian blobs: cutoff_sigmas = {} (x sigma {} voxel); it must be >= 1 and the box "
                                "half-width cutoff_sigmas * sigma_voxel <= {} voxel",
                                cutoff_sigmas, sigma_voxel, kMaxAxisVoxels / 2 - 1));
  if (threads < 0) throw bad_input(fmt::format("gaussian blobs: threads = {}; use 0 (default) or > 0", threads));
}

SparseVolume gaussian_blob_volume(const VoxelGrid& grid, std::span<const Vec3d> particles_mm,
                                  const GaussianBlobOptions& options) {
  options.validate();
  particles::detail::check_grid(grid, "gaussian blobs");
  for (std::size_t p = 0; p < particles_mm.size(); ++p) {
    const Vec3d& w = particles_mm[p];
    if (!std::isfinite(w.x) || !std::isfinite(w.y) || !std::isfinite(w.z))
      throw bad_input(fmt::format("gaussian blobs: particle {} has a non-finite position; remove it", p));
  }
  const double half = options.cutoff_sigmas * options.sigma_voxel;
  const double inv_two_sigma2 = 1.0 / (2.0 * options.sigma_voxel * options.sigma_voxel);
  const std::size_t rows = static_cast<std::size_t>(grid.ny) * static_cast<std::size_t>(grid.nz);

  // Pass 1: the box of each particle and the number of entries it adds to each (j, k) row, so
  // every row's entries land in their own contiguous bucket, sortable on their own.
  std::vector<Box> boxes(particles_mm.size());
  std::vector<Vec3d> centres(particles_mm.size());
  std::vector<std::uint64_t> row_start(rows + 1, 0);
  for (std::size_t p = 0; p < particles_mm.size(); ++p) {
    const Vec3d c = grid.voxel_of(particles_mm[p]);
    centres[p] = c;
    Box& b = boxes[p];
    if (!axis_range(c.x, half, grid.nx, b.i0, b.i1) || !axis_range(c.y, half, grid.ny, b.j0, b.j1) ||
        !axis_range(c.z, half, grid.nz, b.k0, b.k1)) {
      b = {0, -1, 0, -1, 0, -1};
      continue;
    }
    const int width = b.i1 - b.i0 + 1;
    for (int k = b.k0; k <= b.k1; ++k)
      for (int j = b.j0; j <= b.j1; ++j) row_start[static_cast<std::size_t>(j) + grid.ny * static_cast<std::size_t>(k) + 1] += width;
  }
  for (std::size_t r = 0; r < rows; ++r) row_start[r + 1] += row_start[r];

  // Pass 2: fill the buckets in particle order (separable weights: wx * wy * wz).
  std::vector<Entry> entries(row_start[rows]);
  std::vector<std::uint64_t> cursor(row_start.begin(), row_start.end() - 1);
  double wx[kMaxAxisVoxels], wy[kMaxAxisVoxels], wz[kMaxAxisVoxels];
  for (std::size_t p = 0; p < particles_mm.size(); ++p) {
    const Box& b = boxes[p];
    if (b.i1 < b.i0) continue;
    const Vec3d& c = centres[p];
    for (int i = b.i0; i <= b.i1; ++i) wx[i - b.i0] = std::exp(-(i - c.x) * (i - c.x) * inv_two_sigma2);
    for (int j = b.j0; j <= b.j1; ++j) wy[j - b.j0] = std::exp(-(j - c.y) * (j - c.y) * inv_two_sigma2);
    for (int k = b.k0; k <= b.k1; ++k) wz[k - b.k0] = options.peak * std::exp(-(k - c.z) * (k - c.z) * inv_two_sigma2);
    for (int k = b.k0; k <= b.k1; ++k)
      for (int j = b.j0; j <= b.j1; ++j) {
        const std::size_t row = static_cast<std::size_t>(j) + grid.ny * static_cast<std::size_t>(k);
        const double wjk = wy[j - b.j0] * wz[k - b.k0];
        Entry* out = entries.data() + cursor[row];
        const std::uint32_t base = static_cast<std::uint32_t>(row * grid.nx);
        for (int i = b.i0; i <= b.i1; ++i)
          *out++ = {base + static_cast<std::uint32_t>(i), static_cast<float>(wx[i - b.i0] * wjk)};
        cursor[row] += b.i1 - b.i0 + 1;
      }
  }

  // Pass 3, per row: sort by (index, value) so overlapping particles sum in a fixed order,
  // then merge duplicates in place. Rows are independent, so threads never share data.
  std::vector<std::uint64_t> kept(rows + 1, 0);
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
  for (std::int64_t r = 0; r < static_cast<std::int64_t>(rows); ++r) {
    Entry* first = entries.data() + row_start[r];
    Entry* last = entries.data() + row_start[r + 1];
    if (first == last) continue;
    std::sort(first, last, [](const Entry& a, const Entry& b) {
      return a.index < b.index || (a.index == b.index && a.value < b.value);
    });
    Entry* out = first;
    for (Entry* e = first; e != last;) {
      double sum = 0.0;
      const std::uint32_t index = e->index;
      for (; e != last && e->index == index; ++e) sum += e->value;
      *out++ = {index, static_cast<float>(sum)};
    }
    kept[r + 1] = static_cast<std::uint64_t>(out - first);
  }
  for (std::size_t r = 0; r < rows; ++r) kept[r + 1] += kept[r];

  SparseVolume volume;
  volume.grid = grid;
  volume.index.resize(kept[rows]);
  volume.intensity.resize(kept[rows]);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
  for (std::int64_t r = 0; r < static_cast<std::int64_t>(rows); ++r) {
    const Entry* in = entries.data() + row_start[r];
    for (std::uint64_t n = kept[r]; n < kept[r + 1]; ++n, ++in) {
      volume.index[n] = in->index;
      volume.intensity[n] = in->value;
    }
  }
  return volume;
}

}  // namespace tomorig::quality
