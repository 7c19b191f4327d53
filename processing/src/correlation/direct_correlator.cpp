#include "correlation/direct_correlator.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "tomorig/processing/correlation/peak_fit.h"

namespace tomorig::piv::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

int ceil_div(int a, int b) { return (a + b - 1) / b; }

int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }

// Circular autocorrelation of one axis's weights at lags -2..2.
void weight_autocorrelation(const std::vector<float>& w, double out[5]) {
  const int n = static_cast<int>(w.size());
  for (int d = -2; d <= 2; ++d) {
    double sum = 0;
    for (int i = 0; i < n; ++i) sum += static_cast<double>(w[i]) * w[wrap(((i + d) % n + n) % n, n)];
    out[d + 2] = sum;
  }
}

// The sums of one window's entries that Eq. 2.16 needs beside the lag products.
struct WindowSums {
  double sum = 0, weighted = 0, weighted_square = 0;  // sum A, sum w^2 A, sum w^2 A^2
};

inline int lag_index(int dx, int dy, int dz) { return (dx + 1) + 3 * ((dy + 1) + 3 * (dz + 1)); }

}  // namespace

void list_occupied(const VolumeView& v, Int3 block, float relative_threshold, int threads, OccupiedVoxels& o) {
  o.block = block;
  o.blocks = {ceil_div(v.nx, block.x), ceil_div(v.ny, block.y), ceil_div(v.nz, block.z)};
  const std::size_t block_count = static_cast<std::size_t>(o.blocks.x) * o.blocks.y * o.blocks.z;
  const std::size_t voxels = v.count();
  float largest = 0.0f;
#pragma omp parallel for num_threads(threads) reduction(max : largest) schedule(static)
  for (long long n = 0; n < static_cast<long long>(voxels); ++n) largest = std::max(largest, std::abs(v.data[n]));
  const float threshold = relative_threshold * largest;
  std::vector<std::size_t>& counts = o.offsets;  // counts, then their running sum, then fill cursors
  counts.assign(block_count + 1, 0);
  auto block_of = [&](int x, int y, int z) {
    return static_cast<std::size_t>(x / block.x) +
           static_cast<std::size_t>(o.blocks.x) * (y / block.y + static_cast<std::size_t>(o.blocks.y) * (z / block.z));
  };
  // Each block-slab of z is one iteration, so every block is counted and filled by one thread,
  // in scan order: the lists do not depend on the thread count.
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int bz = 0; bz < o.blocks.z; ++bz)
    for (int z = bz * block.z; z < std::min(v.nz, (bz + 1) * block.z); ++z)
      for (int y = 0; y < v.ny; ++y) {
        const float* row = v.data + v.linear(0, y, z);
        for (int x = 0; x < v.nx; ++x)
          if (std::abs(row[x]) > threshold) ++counts[block_of(x, y, z) + 1];
      }
  for (std::size_t b = 0; b < block_count; ++b) counts[b + 1] += counts[b];
  o.entries.resize(counts[block_count]);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int bz = 0; bz < o.blocks.z; ++bz)
    for (int z = bz * block.z; z < std::min(v.nz, (bz + 1) * block.z); ++z)
      for (int y = 0; y < v.ny; ++y) {
        const float* row = v.data + v.linear(0, y, z);
        for (int x = 0; x < v.nx; ++x)
          if (std::abs(row[x]) > threshold)
            o.entries[counts[block_of(x, y, z)]++] = {static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                                                      static_cast<std::uint16_t>(z), row[x]};
      }
  // The fill advanced each block's start to the next block's: shift back by one block.
  for (std::size_t b = block_count; b > 0; --b) counts[b] = counts[b - 1];
  counts[0] = 0;
  o.occupied_fraction = voxels ? static_cast<double>(o.entries.size()) / static_cast<double>(voxels) : 0.0;
}

DirectCorrelator::DirectCorrelator(Int3 window, WindowWeighting weighting, double gaussian_sigma)
    : window_(window),
      wx_(axis_weights(window.x, weighting, gaussian_sigma)),
      wy_(axis_weights(window.y, weighting, gaussian_sigma)),
      wz_(axis_weights(window.z, weighting, gaussian_sigma)) {
  double ex = 0, ey = 0, ez = 0;
  for (float w : wx_) ex += static_cast<double>(w) * w;
  for (float w : wy_) ey += static_cast<double>(w) * w;
  for (float w : wz_) ez += static_cast<double>(w) * w;
  weight_energy_ = ex * ey * ez;
  auto padded = [](const std::vector<float>& w) {
    const int n = static_cast<int>(w.size());
    std::vector<float> p(n + 4);
    for (int i = -2; i < n + 2; ++i) p[i + 2] = w[((i % n) + n) % n];
    return p;
  };
  px_ = padded(wx_);
  py_ = padded(wy_);
  pz_ = padded(wz_);
  weight_autocorrelation(wx_, kx_);
  weight_autocorrelation(wy_, ky_);
  weight_autocorrelation(wz_, kz_);
}

WindowPeak DirectCorrelator::correlate(const OccupiedVoxels& oa, const VolumeView& vb, const OccupiedVoxels& ob,
                                       Int3 start, Scratch& s, bool& fallback) const {
  fallback = false;
  WindowPeak result;
  const auto t0 = Clock::now();
  const Int3 w = window_;
  const double n = static_cast<double>(w.x) * w.y * w.z;
  // Visits the entries of `o` inside the window: f(i, j, k, value) in window coordinates.
  auto for_window_entries = [&](const OccupiedVoxels& o, auto&& f) {
    const int bx0 = std::max(0, start.x) / o.block.x, bx1 = std::min(o.blocks.x - 1, (start.x + w.x - 1) / o.block.x);
    const int by0 = std::max(0, start.y) / o.block.y, by1 = std::min(o.blocks.y - 1, (start.y + w.y - 1) / o.block.y);
    const int bz0 = std::max(0, start.z) / o.block.z, bz1 = std::min(o.blocks.z - 1, (start.z + w.z - 1) / o.block.z);
    for (int bz = bz0; bz <= bz1; ++bz)
      for (int by = by0; by <= by1; ++by)
        for (int bx = bx0; bx <= bx1; ++bx) {
          const std::size_t b = bx + static_cast<std::size_t>(o.blocks.x) * (by + static_cast<std::size_t>(o.blocks.y) * bz);
          // A block wholly inside the window (every block when windows start on the block
          // grid, as the passes' do) needs no test per entry.
          const bool whole = bx * o.block.x >= start.x && (bx + 1) * o.block.x <= start.x + w.x &&
                             by * o.block.y >= start.y && (by + 1) * o.block.y <= start.y + w.y &&
                             bz * o.block.z >= start.z && (bz + 1) * o.block.z <= start.z + w.z;
          for (std::size_t e = o.offsets[b]; e < o.offsets[b + 1]; ++e) {
            const OccupiedVoxels::Entry& v = o.entries[e];
            const int i = v.x - start.x, j = v.y - start.y, k = v.z - start.z;
            if (!whole && (i < 0 || j < 0 || k < 0 || i >= w.x || j >= w.y || k >= w.z)) continue;
            f(i, j, k, v.value);
          }
        }
  };

  // Window a: its sums, and its entries (weighted) for the lag products.
  WindowSums sa, sb;
  s.a_weight.clear();
  s.a_i.clear();
  s.a_j.clear();
  s.a_k.clear();
  for_window_entries(oa, [&](int i, int j, int k, float value) {
    const float weight = wx_[i] * wy_[j] * wz_[k];
    const double w2 = static_cast<double>(weight) * weight;
    sa.sum += value;
    sa.weighted += w2 * value;
    sa.weighted_square += w2 * value * value;
    s.a_weight.push_back(weight * value);
    s.a_i.push_back(static_cast<std::uint16_t>(i));
    s.a_j.push_back(static_cast<std::uint16_t>(j));
    s.a_k.push_back(static_cast<std::uint16_t>(k));
  });
  // Window b: its sums, and QB(s) = sum_y w(y) B(y) w(y - s) at the 27 lags.
  double qb[27] = {};
  alignas(16) float qb4[9][4] = {};  // per (dy, dz) row, x lags as 4 float lanes (the 4th unused)
  for_window_entries(ob, [&](int i, int j, int k, float value) {
    const float weight = wx_[i] * wy_[j] * wz_[k];
    const double w2 = static_cast<double>(weight) * weight;
    sb.sum += value;
    sb.weighted += w2 * value;
    sb.weighted_square += w2 * value * value;
    const float wb = weight * value;
    float py[3], pz[3];
    alignas(16) float px[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    for (int d = -1; d <= 1; ++d) {
      px[d + 1] = px_[i - d + 2];
      py[d + 1] = py_[j - d + 2];
      pz[d + 1] = pz_[k - d + 2];
    }
    for (int dz = 0; dz < 3; ++dz)
      for (int dy = 0; dy < 3; ++dy) {
        const float f = wb * pz[dz] * py[dy];
        float* q = qb4[dy + 3 * dz];
#pragma omp simd
        for (int l = 0; l < 4; ++l) q[l] += f * px[l];
      }
  });
  for (int r = 0; r < 9; ++r)
    for (int l = 0; l < 3; ++l) qb[3 * r + l] = qb4[r][l];
  const double mean_a = sa.sum / n, mean_b = sb.sum / n;
  // sum w^2 (A - mean)^2 over the whole window, the empty voxels included.
  const double energy_a = sa.weighted_square - 2 * mean_a * sa.weighted + mean_a * mean_a * weight_energy_;
  const double energy_b = sb.weighted_square - 2 * mean_b * sb.weighted + mean_b * mean_b * weight_energy_;
  const auto t1 = Clock::now();
  s.seconds.load += seconds_between(t0, t1);
  if (!(energy_a > 1e-20) || !(energy_b > 1e-20)) {
    result.empty = true;
    return result;
  }

  // P(s) = sum_x w(x) A(x) w(x+s) B(x+s) and QA(s) = sum_x w(x) A(x) w(x+s), circular in the
  // window as the FFT's correlation, B read from its volume (0 outside).
  auto b_at = [&](int i, int j, int k) -> float {
    const int x = start.x + i, y = start.y + j, z = start.z + k;
    if (x < 0 || y < 0 || z < 0 || x >= vb.nx || y >= vb.ny || z >= vb.nz) return 0.0f;
    return vb.data[vb.linear(x, y, z)];
  };
  double p[27] = {}, qa[27] = {};            // the edge entries, and the sums at the end
  alignas(16) float p4[9][4] = {}, qa4[9][4] = {};  // the interior entries: per (dy, dz) row, 4 x lanes
  const std::size_t count = s.a_weight.size();
  const std::size_t sy = static_cast<std::size_t>(vb.nx), sz = sy * static_cast<std::size_t>(vb.ny);
  const bool inside = start.x >= 0 && start.y >= 0 && start.z >= 0 && start.x + w.x <= vb.nx &&
                      start.y + w.y <= vb.ny && start.z + w.z <= vb.nz;
  for (std::size_t e = 0; e < count; ++e) {
    const int i = s.a_i[e], j = s.a_j[e], k = s.a_k[e];
    const float wa = s.a_weight[e];
    float px[3], py[3], pz[3];
    for (int d = -1; d <= 1; ++d) {
      px[d + 1] = px_[i + d + 2];
      py[d + 1] = py_[j + d + 2];
      pz[d + 1] = pz_[k + d + 2];
    }
    // Interior: no wrap, no bounds, and the row's fourth value (weight 0) is inside the volume.
    const bool interior = inside && i >= 1 && j >= 1 && k >= 1 && i + 2 < w.x && j + 1 < w.y && k + 1 < w.z;
    if (interior) {
      // The 3 x 3 x 3 neighbourhood straight from the volume, x lags as 4 float lanes.
      const float* centre = vb.data + vb.linear(start.x + i, start.y + j, start.z + k);
      const float lanes[4] = {px[0], px[1], px[2], 0.0f};
      for (int dz = 0; dz < 3; ++dz)
        for (int dy = 0; dy < 3; ++dy) {
          const float f = wa * pz[dz] * py[dy];
          const float* row = centre + (dz - 1) * sz + (dy - 1) * sy - 1;
          float* pr = p4[dy + 3 * dz];
          float* qr = qa4[dy + 3 * dz];
#pragma omp simd
          for (int l = 0; l < 4; ++l) {
            const float g = f * lanes[l];
            pr[l] += g * row[l];
            qr[l] += g;
          }
        }
      continue;
    }
    // Edge of the window: the lags wrap around it (as the FFT's). Each axis's three wrapped
    // coordinates are looked up once; a coordinate outside the volume reads 0.
    std::ptrdiff_t ox[3], oy[3], oz[3];
    bool in_x[3], in_y[3], in_z[3];
    for (int d = -1; d <= 1; ++d) {
      const int x = start.x + wrap(i + d, w.x), y = start.y + wrap(j + d, w.y), z = start.z + wrap(k + d, w.z);
      in_x[d + 1] = x >= 0 && x < vb.nx;
      in_y[d + 1] = y >= 0 && y < vb.ny;
      in_z[d + 1] = z >= 0 && z < vb.nz;
      ox[d + 1] = x;
      oy[d + 1] = static_cast<std::ptrdiff_t>(y) * static_cast<std::ptrdiff_t>(sy);
      oz[d + 1] = static_cast<std::ptrdiff_t>(z) * static_cast<std::ptrdiff_t>(sz);
    }
    for (int dz = 0; dz < 3; ++dz)
      for (int dy = 0; dy < 3; ++dy) {
        const float fzy = wa * pz[dz] * py[dy];
        const bool row_in = in_z[dz] && in_y[dy];
        const float* row = vb.data + (row_in ? oz[dz] + oy[dy] : 0);
        double* pl = p + 3 * (dy + 3 * dz);
        double* ql = qa + 3 * (dy + 3 * dz);
        for (int dx = 0; dx < 3; ++dx) {
          const float f = fzy * px[dx];
          pl[dx] += f * (row_in && in_x[dx] ? row[ox[dx]] : 0.0f);
          ql[dx] += f;
        }
      }
  }
  for (int r = 0; r < 9; ++r)
    for (int l = 0; l < 3; ++l) {
      p[3 * r + l] += p4[r][l];
      qa[3 * r + l] += qa4[r][l];
    }
  // R(s) = sum w(x) w(x+s) (A(x) - mean_a) (B(x+s) - mean_b), expanded.
  auto combine = [&](double p_s, double qa_s, double qb_s, int dx, int dy, int dz) {
    const double k = kx_[dx + 2] * ky_[dy + 2] * kz_[dz + 2];
    return p_s - mean_b * qa_s - mean_a * qb_s + mean_a * mean_b * k;
  };
  double r[27];
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int l = lag_index(dx, dy, dz);
        r[l] = combine(p[l], qa[l], qb[l], dx, dy, dz);
      }
  // One lag outside the 27 (a peak's outer neighbour at +-2 along one axis), computed alone.
  auto single_lag = [&](int dx, int dy, int dz) {
    double ps = 0, qas = 0, qbs = 0;
    for (std::size_t e = 0; e < count; ++e) {
      const int i = wrap(s.a_i[e] + dx, w.x), j = wrap(s.a_j[e] + dy, w.y), k = wrap(s.a_k[e] + dz, w.z);
      const float f = s.a_weight[e] * wx_[i] * wy_[j] * wz_[k];
      ps += f * b_at(i, j, k);
      qas += f;
    }
    for_window_entries(ob, [&](int i, int j, int k, float value) {
      qbs += static_cast<double>(wx_[i] * wy_[j] * wz_[k] * value) * wx_[wrap(i - dx, w.x)] * wy_[wrap(j - dy, w.y)] *
             wz_[wrap(k - dz, w.z)];
    });
    return combine(ps, qas, qbs, dx, dy, dz);
  };
  const auto t2 = Clock::now();
  s.seconds.correlation += seconds_between(t1, t2);

  int best = 0;
  for (int l = 1; l < 27; ++l)
    if (r[l] > r[best]) best = l;
  const int mx = best % 3 - 1, my = (best / 3) % 3 - 1, mz = best / 9 - 1;
  const double centre = r[best];
  auto value_at = [&](int dx, int dy, int dz) {
    if (std::abs(dx) <= 1 && std::abs(dy) <= 1 && std::abs(dz) <= 1) return r[lag_index(dx, dy, dz)];
    return single_lag(dx, dy, dz);
  };
  double left[3], right[3];
  const int m[3] = {mx, my, mz};
  for (int axis = 0; axis < 3; ++axis) {
    int lo[3] = {mx, my, mz}, hi[3] = {mx, my, mz};
    lo[axis] -= 1;
    hi[axis] += 1;
    left[axis] = value_at(lo[0], lo[1], lo[2]);
    right[axis] = value_at(hi[0], hi[1], hi[2]);
    // The peak continues beyond the lags searched: let the FFT find it.
    if (left[axis] > centre || right[axis] > centre) {
      fallback = true;
      s.seconds.peak += seconds_between(t2, Clock::now());
      return result;
    }
  }
  float offsets[3];
  for (int axis = 0; axis < 3; ++axis) {
    const PeakFit1d fit = fit_peak_1d(left[axis], centre, right[axis], true, true);
    if (fit.method != PeakFitMethod::gaussian) ++result.fallbacks;
    offsets[axis] = static_cast<float>(m[axis] + fit.offset);
  }
  result.dx = offsets[0];
  result.dy = offsets[1];
  result.dz = offsets[2];
  result.peak = static_cast<float>(centre / std::sqrt(energy_a * energy_b));
  result.valid = true;
  s.seconds.peak += seconds_between(t2, Clock::now());
  return result;
}

}  // namespace tomorig::piv::detail
