#include "tomorig/processing/particles/extraction.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>

#include <fmt/core.h>

#include "particles/sparse_rows.h"
#include "particles/volume_checks.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/particles/sparsify.h"

namespace tomorig::particles {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Running sums of one blob, relative to its peak voxel so large grids keep full precision.
struct BlobSums {
  double sum = 0, si = 0, sj = 0, sk = 0;
  int count = 0;
  int pi = 0, pj = 0, pk = 0;  // the peak voxel
  int min_i = 0, min_j = 0, min_k = 0, max_i = 0, max_j = 0, max_k = 0;
};

}  // namespace

void ExtractionOptions::validate() const {
  if (!std::isfinite(voxel_floor))
    throw bad_input(fmt::format("particle extraction: voxel_floor = {}; it must be finite", voxel_floor));
  if (!std::isfinite(peak_threshold))
    throw bad_input(fmt::format("particle extraction: peak_threshold = {}; it must be finite", peak_threshold));
  if (!(relative_peak_threshold >= 0.0 && relative_peak_threshold < 1.0))
    throw bad_input(fmt::format("particle extraction: relative_peak_threshold = {}; it must be in [0, 1)",
                                relative_peak_threshold));
  if (max_radius_voxel < 1)
    throw bad_input(fmt::format("particle extraction: max_radius_voxel = {}; it must be >= 1", max_radius_voxel));
  if (threads < 0)
    throw bad_input(fmt::format("particle extraction: threads = {}; use 0 (default) or > 0", threads));
}

std::string ExtractionReport::brief() const {
  return fmt::format("{} particles from {} local maxima above {:.4g} ({} active voxels) in {:.3f} s", particles.size(),
                     local_maxima, peak_cutoff, active_voxels, seconds);
}

ExtractionReport extract_particles(const SparseVolume& volume, const ExtractionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.validate();
  detail::check_sparse(volume, "particle extraction");
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  const std::size_t n = volume.size();
  const float* value = volume.intensity.data();
  const float floor = options.voxel_floor;
  const detail::SparseRows rows(volume.grid, volume.index);

  // Steepest ascent: each active voxel points at its brightest neighbour when that one is
  // brighter, in the strict order (value, index), so every chain ends at one maximum.
  std::vector<std::uint32_t> parent(n, kNone);
  float brightest = 0.0f;
  std::size_t active = 0;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads) reduction(max : brightest) reduction(+ : active)
  for (std::int64_t row = 0; row < static_cast<std::int64_t>(rows.row_count()); ++row) {
    rows.visit_row(row, 26, [&](std::size_t e, const detail::Voxel&, const std::uint32_t* neighbours, int count) {
      if (!(value[e] > floor)) return;
      ++active;
      brightest = std::max(brightest, value[e]);
      std::size_t best = e;
      for (int c = 0; c < count; ++c) {
        const std::size_t m = neighbours[c];
        if (value[m] > value[best] || (value[m] == value[best] && m > best)) best = m;
      }
      parent[e] = static_cast<std::uint32_t>(best);
    });
  }

  // Resolve each chain to its maximum. Chains are short (a few voxels up a blob's flank), so
  // following them read-only in parallel beats a sequential walk with path compression.
  std::vector<std::uint32_t> root(n, kNone);
#pragma omp parallel for schedule(dynamic, 4096) num_threads(threads)
  for (std::int64_t e = 0; e < static_cast<std::int64_t>(n); ++e) {
    if (parent[e] == kNone) continue;
    std::uint32_t r = static_cast<std::uint32_t>(e);
    while (parent[r] != r) r = parent[r];
    root[e] = r;
  }

  ExtractionReport report;
  report.active_voxels = active;
  report.peak_cutoff = std::max(options.peak_threshold, static_cast<float>(options.relative_peak_threshold * brightest));
  std::vector<std::int32_t> blob_of_root(n, -1);
  std::vector<BlobSums> blobs;
  for (std::size_t e = 0; e < n; ++e) {
    if (root[e] != e) continue;
    ++report.local_maxima;
    if (!(value[e] > report.peak_cutoff)) continue;
    blob_of_root[e] = static_cast<std::int32_t>(blobs.size());
    const detail::Voxel c = rows.voxel_of(e);
    BlobSums b;
    b.pi = c.i, b.pj = c.j, b.pk = c.k;
    b.min_i = b.max_i = c.i;
    b.min_j = b.max_j = c.j;
    b.min_k = b.max_k = c.k;
    blobs.push_back(b);
  }

  // Sums per blob, row by row so each voxel's coordinates come without divisions.
  const int radius = options.max_radius_voxel;
  const std::uint32_t nx = static_cast<std::uint32_t>(volume.grid.nx);
  for (std::size_t row = 0; row < rows.row_count(); ++row) {
    const auto [first, last] = rows.row_range(row);
    if (first == last) continue;
    const int j = static_cast<int>(row % static_cast<std::size_t>(volume.grid.ny));
    const int k = static_cast<int>(row / static_cast<std::size_t>(volume.grid.ny));
    const std::uint32_t base = static_cast<std::uint32_t>(row) * nx;
    for (std::uint32_t e = first; e < last; ++e) {
      if (root[e] == kNone) continue;
      const std::int32_t id = blob_of_root[root[e]];
      if (id < 0) continue;
      BlobSums& b = blobs[id];
      const int i = static_cast<int>(volume.index[e] - base);
      const int di = i - b.pi, dj = j - b.pj, dk = k - b.pk;
      if (std::abs(di) > radius || std::abs(dj) > radius || std::abs(dk) > radius) continue;
      const double v = value[e];
      b.sum += v;
      b.si += v * di;
      b.sj += v * dj;
      b.sk += v * dk;
      ++b.count;
      b.min_i = std::min(b.min_i, i), b.max_i = std::max(b.max_i, i);
      b.min_j = std::min(b.min_j, j), b.max_j = std::max(b.max_j, j);
      b.min_k = std::min(b.min_k, k), b.max_k = std::max(b.max_k, k);
    }
  }

  report.particles.reserve(blobs.size());
  for (std::size_t e = 0; e < n; ++e) {
    if (root[e] != e || blob_of_root[e] < 0) continue;
    const BlobSums& b = blobs[blob_of_root[e]];
    Particle particle;
    particle.voxel = {b.pi + b.si / b.sum, b.pj + b.sj / b.sum, b.pk + b.sk / b.sum};
    particle.world = volume.grid.centre_of(particle.voxel.x, particle.voxel.y, particle.voxel.z);
    particle.peak_index = volume.index[e];
    particle.peak = value[e];
    particle.integrated = b.sum;
    particle.voxel_count = b.count;
    particle.min_i = b.min_i, particle.min_j = b.min_j, particle.min_k = b.min_k;
    particle.max_i = b.max_i, particle.max_j = b.max_j, particle.max_k = b.max_k;
    report.particles.push_back(particle);
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

ExtractionReport extract_particles(const DenseVolume& volume, const ExtractionOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  options.validate();
  detail::check_grid(volume.grid, "particle extraction");
  ExtractionReport report = extract_particles(sparsify(volume, options.voxel_floor, options.threads), options);
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace tomorig::particles
