#include "tomorig/processing/quality/quality_factor.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

// Fixed number of work chunks (not the thread count): each keeps its own sums, added in chunk
// order at the end, so the floating-point result is the same on 1 or N threads.
constexpr int kChunks = 32;

struct Sums {
  double ee = 0, gg = 0, eg = 0;
};

// For each coordinate of an axis, the first and last window holding it (contiguous, since
// origins ascend and windows have equal length).
struct AxisWindows {
  std::vector<int> first, last;
  int count = 0;
};

AxisWindows axis_windows(int length, const WindowOptions& options) {
  const std::vector<int> origins = window_origins(length, options);
  const int size = std::min(options.size, length);
  AxisWindows a;
  a.count = static_cast<int>(origins.size());
  a.first.assign(length, 0);
  a.last.assign(length, -1);
  for (int c = 0; c < length; ++c) {
    int f = 0;
    while (f < a.count && origins[f] + size <= c) ++f;
    int l = a.count - 1;
    while (l >= 0 && origins[l] > c) --l;
    a.first[c] = f;
    a.last[c] = l;
  }
  return a;
}

double correlation(const Sums& s) {
  if (s.ee <= 0.0 || s.gg <= 0.0) return 0.0;
  return s.eg / std::sqrt(s.ee * s.gg);
}

}  // namespace

void WindowOptions::validate() const {
  if (size < 1) throw bad_input(fmt::format("quality windows: size = {}; it must be >= 1 voxel", size));
  if (step < 1 || step > size)
    throw bad_input(fmt::format("quality windows: step = {}; it must be in [1, size = {}] so windows cover the grid",
                                step, size));
}

std::vector<int> window_origins(int length, const WindowOptions& options) {
  options.validate();
  if (length <= options.size) return {0};
  std::vector<int> origins;
  for (int o = 0; o + options.size <= length; o += options.step) origins.push_back(o);
  if (origins.back() + options.size < length) origins.push_back(length - options.size);
  return origins;
}

QualityFactor quality_factor(const SparseVolume& reconstruction, const SparseVolume& truth,
                             const WindowOptions& windows, int threads) {
  windows.validate();
  particles::detail::check_sparse(reconstruction, "quality factor (reconstruction)");
  particles::detail::check_sparse(truth, "quality factor (truth)");
  particles::detail::check_same_grid(reconstruction.grid, truth.grid, "the reconstruction", "the truth volume");
  const VoxelGrid& g = truth.grid;
  const AxisWindows ax = axis_windows(g.nx, windows), ay = axis_windows(g.ny, windows),
                    az = axis_windows(g.nz, windows);
  const std::size_t window_count = static_cast<std::size_t>(ax.count) * ay.count * az.count;

  // Chunk c covers linear indices [bound[c], bound[c + 1]); each list is split there by
  // binary search, so chunks merge independently.
  const std::uint64_t total = g.voxel_count();
  std::vector<Sums> chunk_sums(static_cast<std::size_t>(kChunks) * (window_count + 1));
  const int used = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel for schedule(dynamic, 1) num_threads(used)
  for (int c = 0; c < kChunks; ++c) {
    const std::uint64_t lo = total * c / kChunks, hi = total * (c + 1) / kChunks;
    const auto span_of = [&](const std::vector<std::uint32_t>& index) {
      const auto first = std::lower_bound(index.begin(), index.end(), lo);
      const auto last = std::lower_bound(first, index.end(), hi);
      return std::pair<std::size_t, std::size_t>(first - index.begin(), last - index.begin());
    };
    auto [e, e_end] = span_of(reconstruction.index);
    auto [t, t_end] = span_of(truth.index);
    Sums* window_sums = chunk_sums.data() + static_cast<std::size_t>(c) * (window_count + 1);
    Sums& grid_sums = window_sums[window_count];
    const std::uint32_t nx = static_cast<std::uint32_t>(g.nx), ny = static_cast<std::uint32_t>(g.ny);
    while (e < e_end || t < t_end) {
      std::uint32_t index;
      double ev = 0.0, gv = 0.0;
      if (t == t_end || (e < e_end && reconstruction.index[e] < truth.index[t])) {
        index = reconstruction.index[e];
        ev = reconstruction.intensity[e++];
      } else if (e == e_end || truth.index[t] < reconstruction.index[e]) {
        index = truth.index[t];
        gv = truth.intensity[t++];
      } else {
        index = truth.index[t];
        ev = reconstruction.intensity[e++];
        gv = truth.intensity[t++];
      }
      const double ee = ev * ev, gg = gv * gv, eg = ev * gv;
      grid_sums.ee += ee, grid_sums.gg += gg, grid_sums.eg += eg;
      const std::uint32_t row = index / nx;
      const int i = static_cast<int>(index - row * nx), j = static_cast<int>(row % ny), k = static_cast<int>(row / ny);
      for (int wz = az.first[k]; wz <= az.last[k]; ++wz)
        for (int wy = ay.first[j]; wy <= ay.last[j]; ++wy) {
          Sums* base = window_sums + ax.count * (wy + static_cast<std::size_t>(ay.count) * wz);
          for (int wx = ax.first[i]; wx <= ax.last[i]; ++wx) {
            Sums& s = base[wx];
            s.ee += ee, s.gg += gg, s.eg += eg;
          }
        }
    }
  }

  std::vector<Sums> sums(window_count + 1);
  for (int c = 0; c < kChunks; ++c)
    for (std::size_t w = 0; w <= window_count; ++w) {
      const Sums& s = chunk_sums[static_cast<std::size_t>(c) * (window_count + 1) + w];
      sums[w].ee += s.ee, sums[w].gg += s.gg, sums[w].eg += s.eg;
    }

  QualityFactor q;
  q.global = correlation(sums[window_count]);
  q.windows = window_count;
  q.windows_x = ax.count, q.windows_y = ay.count, q.windows_z = az.count;
  q.window_q.assign(window_count, std::numeric_limits<double>::quiet_NaN());
  double sum_q = 0.0;
  for (std::size_t w = 0; w < window_count; ++w) {
    if (sums[w].ee <= 0.0 && sums[w].gg <= 0.0) continue;
    q.window_q[w] = correlation(sums[w]);
    sum_q += q.window_q[w];
    ++q.windows_used;
  }
  q.windowed = q.windows_used > 0 ? sum_q / q.windows_used : 0.0;
  return q;
}

}  // namespace tomorig::quality
