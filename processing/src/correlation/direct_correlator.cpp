#include "correlation/direct_correlator.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "correlation/direct_peak.h"
#include "correlation/window_lag_sums.h"

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
    for (int i = 0; i < n; ++i) sum += static_cast<double>(w[i]) * w[((i + d) % n + n) % n];
    out[d + 2] = sum;
  }
}

}  // namespace

void list_occupied(const VolumeView& v, Int3 block, float relative_threshold, float largest, int threads,
                   OccupiedVoxels& o, bool faces) {
  o.block = block;
  o.blocks = {ceil_div(v.nx, block.x), ceil_div(v.ny, block.y), ceil_div(v.nz, block.z)};
  const std::size_t block_count = static_cast<std::size_t>(o.blocks.x) * o.blocks.y * o.blocks.z;
  const std::size_t voxels = v.count();
  const float threshold = relative_threshold * largest;
  std::vector<std::size_t>& counts = o.offsets;  // counts, then their running sum, then fill cursors
  counts.assign(block_count + 1, 0);
  // A voxel's block is its row's block offset plus its x's block column (a table: a division
  // per voxel otherwise).
  std::vector<std::uint32_t> block_x(static_cast<std::size_t>(v.nx));
  for (int x = 0; x < v.nx; ++x) block_x[x] = static_cast<std::uint32_t>(x / block.x);
  auto row_block = [&](int y, int z) {
    return static_cast<std::size_t>(o.blocks.x) * (y / block.y + static_cast<std::size_t>(o.blocks.y) * (z / block.z));
  };
  // Rows are scanned in chunks of kChunk voxels tested at once in float lanes: most chunks of a
  // particle volume are empty and are skipped without a branch per voxel.
  constexpr int kChunk = 16;
  auto chunk_has_signal = [threshold](const float* p) {
    int any = 0;
#pragma omp simd reduction(| : any)
    for (int l = 0; l < kChunk; ++l) any |= std::abs(p[l]) > threshold;
    return any != 0;
  };
  // Calls f(x) for every voxel of the row above the threshold, x ascending.
  auto for_each_above = [&](const float* row, auto&& f) {
    for (int x0 = 0; x0 < v.nx; x0 += kChunk) {
      const int x1 = std::min(v.nx, x0 + kChunk);
      if (x1 - x0 == kChunk && !chunk_has_signal(row + x0)) continue;
      for (int x = x0; x < x1; ++x)
        if (std::abs(row[x]) > threshold) f(x);
    }
  };
  // One sweep over the volume: each block-slab of z is one iteration, whose rows are scanned
  // in order into the slab's own list (which is then its part of the row lists) while its
  // blocks are counted. The block lists are then filled from the slab lists, not from the
  // volume: the volume is read once, not twice (it is hundreds of megabytes; the lists are a
  // few per cent of it). Every block is counted and filled by one thread, in scan order: the
  // lists do not depend on the thread count.
  const std::size_t row_count = static_cast<std::size_t>(v.ny) * v.nz;
  const std::size_t slab_rows = static_cast<std::size_t>(v.ny) * block.z;
  o.row_offsets.assign(row_count + 1, 0);
  o.slab_entries.resize(o.blocks.z);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int bz = 0; bz < o.blocks.z; ++bz) {
    std::vector<OccupiedVoxels::RowEntry>& slab = o.slab_entries[bz];
    slab.clear();
    for (int z = bz * block.z; z < std::min(v.nz, (bz + 1) * block.z); ++z)
      for (int y = 0; y < v.ny; ++y) {
        const float* row = v.data + v.linear(0, y, z);
        std::size_t* row_counts = counts.data() + row_block(y, z) + 1;
        const std::size_t before = slab.size();
        for_each_above(row, [&](int x) {
          ++row_counts[block_x[x]];
          slab.push_back({x, row[x]});
        });
        o.row_offsets[y + static_cast<std::size_t>(v.ny) * z + 1] = slab.size() - before;
      }
  }
  for (std::size_t b = 0; b < block_count; ++b) counts[b + 1] += counts[b];
  for (std::size_t r = 0; r < row_count; ++r) o.row_offsets[r + 1] += o.row_offsets[r];
  o.entries.resize(counts[block_count]);
  o.row_entries.resize(counts[block_count]);
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int bz = 0; bz < o.blocks.z; ++bz) {
    const std::vector<OccupiedVoxels::RowEntry>& slab = o.slab_entries[bz];
    std::copy(slab.begin(), slab.end(), o.row_entries.begin() + o.row_offsets[slab_rows * bz]);
    const OccupiedVoxels::RowEntry* next = slab.data();
    for (int z = bz * block.z; z < std::min(v.nz, (bz + 1) * block.z); ++z)
      for (int y = 0; y < v.ny; ++y) {
        const std::size_t r = y + static_cast<std::size_t>(v.ny) * z;
        std::size_t* cursors = counts.data() + row_block(y, z);
        for (const OccupiedVoxels::RowEntry* end = next + (o.row_offsets[r + 1] - o.row_offsets[r]); next < end; ++next)
          o.entries[cursors[block_x[next->x]]++] = {static_cast<std::uint16_t>(next->x), static_cast<std::uint16_t>(y),
                                                    static_cast<std::uint16_t>(z), next->value};
      }
  }
  // The fill advanced each block's start to the next block's: shift back by one block.
  for (std::size_t b = block_count; b > 0; --b) counts[b] = counts[b - 1];
  counts[0] = 0;
  o.occupied_fraction = voxels ? static_cast<double>(o.entries.size()) / static_cast<double>(voxels) : 0.0;

  // Each block's entries on its six faces, in the block's scan order (counted, then filled, per
  // block: no thread-count dependence).
  auto on_face = [&](const OccupiedVoxels::Entry& e, int f) {
    switch (f) {
      case 0: return e.x % block.x == 0;
      case 1: return e.x % block.x == block.x - 1;
      case 2: return e.y % block.y == 0;
      case 3: return e.y % block.y == block.y - 1;
      case 4: return e.z % block.z == 0;
      default: return e.z % block.z == block.z - 1;
    }
  };
  if (!faces) {
    for (auto& fo : o.face_offsets) fo.clear();
    for (auto& fe : o.face_entries) fe.clear();
    return;
  }
  for (auto& fo : o.face_offsets) fo.assign(block_count + 1, 0);
  // (One parallel loop to count and one to fill all six faces: a parallel region per face cost
  // more in thread wake-ups than the work on a loaded machine.)
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long long b = 0; b < static_cast<long long>(block_count); ++b) {
    std::size_t c[6] = {};
    for (std::size_t e = o.offsets[b]; e < o.offsets[b + 1]; ++e)
      for (int f = 0; f < 6; ++f) c[f] += on_face(o.entries[e], f);
    for (int f = 0; f < 6; ++f) o.face_offsets[f][b + 1] = c[f];
  }
  for (int f = 0; f < 6; ++f) {
    std::vector<std::size_t>& fo = o.face_offsets[f];
    for (std::size_t b = 0; b < block_count; ++b) fo[b + 1] += fo[b];
    o.face_entries[f].resize(fo[block_count]);
  }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (long long b = 0; b < static_cast<long long>(block_count); ++b) {
    std::size_t out[6];
    for (int f = 0; f < 6; ++f) out[f] = o.face_offsets[f][b];
    for (std::size_t e = o.offsets[b]; e < o.offsets[b + 1]; ++e)
      for (int f = 0; f < 6; ++f)
        if (on_face(o.entries[e], f)) o.face_entries[f][out[f]++] = o.entries[e];
  }
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
  auto full_autocorrelation = [](const std::vector<float>& w) {
    const int n = static_cast<int>(w.size());
    std::vector<float> k(n);
    for (int d = 0; d < n; ++d) {
      double sum = 0;
      for (int i = 0; i < n; ++i) sum += static_cast<double>(w[i]) * w[(i + d) % n];
      k[d] = static_cast<float>(sum);
    }
    return k;
  };
  kx_full_ = full_autocorrelation(wx_);
  ky_full_ = full_autocorrelation(wy_);
  kz_full_ = full_autocorrelation(wz_);
  weight_autocorrelation(wx_, kx_);
  weight_autocorrelation(wy_, ky_);
  weight_autocorrelation(wz_, kz_);
}

WindowPeak DirectCorrelator::correlate_from_sums(const float* sums, const OccupiedVoxels& oa, const VolumeView& vb,
                                                 const OccupiedVoxels& ob, Int3 start, Scratch& s,
                                                 bool& fallback, const FaceProducts* faces) const {
  fallback = false;
  WindowPeak result;
  const auto t0 = Clock::now();
  const Int3 w = window_;
  const double n = static_cast<double>(w.x) * w.y * w.z;
  const double mean_a = sums[kSlotSumA] / n, mean_b = sums[kSlotSumB] / n;
  const double energy_a = sums[kSlotW2A2] - 2 * mean_a * sums[kSlotW2A] + mean_a * mean_a * weight_energy_;
  const double energy_b = sums[kSlotW2B2] - 2 * mean_b * sums[kSlotW2B] + mean_b * mean_b * weight_energy_;
  if (!(energy_a > 1e-20) || !(energy_b > 1e-20)) {
    result.empty = true;
    s.seconds.load += seconds_between(t0, Clock::now());
    return result;
  }
  double p[27];
  for (int l = 0; l < 27; ++l) p[l] = sums[kSlotP + l];
  const auto t1 = Clock::now();
  s.seconds.load += seconds_between(t0, t1);

  // The shell: entries with a coordinate at 0 or W - 1, whose lags outward wrap around the
  // window as the FFT's (the contraction left those pairs out of P). Blocks that hold no shell
  // plane are skipped.
  const bool inside = start.x >= 0 && start.y >= 0 && start.z >= 0 && start.x + w.x <= vb.nx &&
                      start.y + w.y <= vb.ny && start.z + w.z <= vb.nz;
  const int bx0 = std::max(0, start.x) / oa.block.x, bx1 = std::min(oa.blocks.x - 1, (start.x + w.x - 1) / oa.block.x);
  const int by0 = std::max(0, start.y) / oa.block.y, by1 = std::min(oa.blocks.y - 1, (start.y + w.y - 1) / oa.block.y);
  const int bz0 = std::max(0, start.z) / oa.block.z, bz1 = std::min(oa.blocks.z - 1, (start.z + w.z - 1) / oa.block.z);
  alignas(16) float p4[9][4] = {};  // per (dy, dz) row, x lags as 4 float lanes (the 4th unused)
  const bool on_borders = inside && w.x % oa.block.x == 0 && w.y % oa.block.y == 0 && w.z % oa.block.z == 0 &&
                          start.x % oa.block.x == 0 && start.y % oa.block.y == 0 && start.z % oa.block.z == 0;
  if (on_borders) {
    // The window covers whole blocks: its shell is the low face of its first blocks and the
    // high face of its last along each axis. Each entry is taken from the first of the six
    // faces (x low, x high, y low, y high, z low, z high) it lies on.
    for (int f = 0; f < 6; ++f) {
      const int axis = f / 2;
      const bool high = f % 2;
      int lo[3] = {bx0, by0, bz0}, hi[3] = {bx1, by1, bz1};
      lo[axis] = hi[axis] = high ? hi[axis] : lo[axis];
      const std::vector<std::size_t>& fo = oa.face_offsets[f];
      const OccupiedVoxels::Entry* fe = oa.face_entries[f].data();
      const float* fp = faces ? faces->values[f].data() : nullptr;
      // The other two axes (u before v), and where a face product's lag (du, dv) goes in p4
      // (float[9][4], row dy + 3 dz, lane dx): base + su du + sv dv.
      const int u = axis == 0 ? 1 : 0, v_axis = axis == 2 ? 1 : 2;
      const int wrapped_slot = high ? 2 : 0;  // the lag index along `axis`
      const int base = axis == 0 ? wrapped_slot : (axis == 1 ? 4 * wrapped_slot : 12 * wrapped_slot);
      const int su = axis == 0 ? 4 : 1, sv = axis == 2 ? 4 : 12;
      const float* pad[3] = {px_.data() + 2, py_.data() + 2, pz_.data() + 2};
      float* p4_flat = &p4[0][0];
      for (int bz = lo[2]; bz <= hi[2]; ++bz)
        for (int by = lo[1]; by <= hi[1]; ++by)
          for (int bx = lo[0]; bx <= hi[0]; ++bx) {
            const std::size_t b = bx + static_cast<std::size_t>(oa.blocks.x) * (by + static_cast<std::size_t>(oa.blocks.y) * bz);
            for (std::size_t e = fo[b]; e < fo[b + 1]; ++e) {
              const OccupiedVoxels::Entry& v = fe[e];
              const int i = v.x - start.x, j = v.y - start.y, k = v.z - start.z;
              if (axis >= 1 && (i == 0 || i == w.x - 1)) continue;  // taken from an x face
              if (axis == 2 && (j == 0 || j == w.y - 1)) continue;  // taken from a y face
              // On this face only (not on an edge of the window): its 9 wrapped products were
              // made once for every window sharing the face.
              const bool edge = (axis == 0 && (j == 0 || j == w.y - 1 || k == 0 || k == w.z - 1)) ||
                                (axis == 1 && (k == 0 || k == w.z - 1));
              if (!fp || edge) {
                add_shell_entry(v, i, j, k, start, vb, inside, p4);
                continue;
              }
              const int c[3] = {i, j, k};
              const float wa = wx_[i] * wy_[j] * wz_[k] * pad[axis][c[axis] + (high ? 1 : -1)];
              const float* product = fp + e * kFaceSlots;
              const float* wu = pad[u] + c[u] - 1;
              const float* wv = pad[v_axis] + c[v_axis] - 1;
              for (int dv = 0; dv < 3; ++dv) {
                const float row = wa * wv[dv];
                float* out = p4_flat + base + sv * dv;
                for (int du = 0; du < 3; ++du) out[su * du] += row * wu[du] * product[du + 3 * dv];
              }
            }
          }
    }
  } else {
    auto holds_shell = [](int b, int size, int first, int last) {  // block b holds plane first or last
      const int lo = b * size, hi = lo + size;
      return (first >= lo && first < hi) || (last >= lo && last < hi);
    };
    for (int bz = bz0; bz <= bz1; ++bz) {
      const bool shell_z = holds_shell(bz, oa.block.z, start.z, start.z + w.z - 1);
      for (int by = by0; by <= by1; ++by) {
        const bool shell_y = holds_shell(by, oa.block.y, start.y, start.y + w.y - 1);
        for (int bx = bx0; bx <= bx1; ++bx) {
          if (!shell_z && !shell_y && !holds_shell(bx, oa.block.x, start.x, start.x + w.x - 1)) continue;
          const std::size_t b = bx + static_cast<std::size_t>(oa.blocks.x) * (by + static_cast<std::size_t>(oa.blocks.y) * bz);
          for (std::size_t e = oa.offsets[b]; e < oa.offsets[b + 1]; ++e) {
            const OccupiedVoxels::Entry& v = oa.entries[e];
            const int i = v.x - start.x, j = v.y - start.y, k = v.z - start.z;
            // (Unsigned: one test each for below 0 and beyond the window.)
            if (static_cast<unsigned>(i) >= static_cast<unsigned>(w.x) ||
                static_cast<unsigned>(j) >= static_cast<unsigned>(w.y) ||
                static_cast<unsigned>(k) >= static_cast<unsigned>(w.z))
              continue;
            if (static_cast<unsigned>(i - 1) < static_cast<unsigned>(w.x - 2) &&
                static_cast<unsigned>(j - 1) < static_cast<unsigned>(w.y - 2) &&
                static_cast<unsigned>(k - 1) < static_cast<unsigned>(w.z - 2))
              continue;  // interior: no lag wraps, all in the contraction
            add_shell_entry(v, i, j, k, start, vb, inside, p4);
          }
        }
      }
    }
  }
  for (int r = 0; r < 9; ++r)
    for (int l = 0; l < 3; ++l) p[3 * r + l] += p4[r][l];

  // R(s) of Eq. 2.16 at the 27 lags.
  double r[27];
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int l = direct_lag_index(dx, dy, dz);
        const double k = kx_[dx + 2] * ky_[dy + 2] * kz_[dz + 2];
        r[l] = p[l] - mean_b * sums[kSlotQA + l] - mean_a * sums[kSlotQB + l] + mean_a * mean_b * k;
      }
  const auto t2 = Clock::now();
  s.seconds.correlation += seconds_between(t1, t2);

  result = direct_peak<1>(
      r, energy_a, energy_b,
      [&](const int (*lags)[3], int count, double* out) { outer_lags(oa, vb, ob, start, lags, count, mean_a, mean_b, out); },
      fallback);
  s.seconds.peak += seconds_between(t2, Clock::now());
  return result;
}

void DirectCorrelator::add_shell_entry(const OccupiedVoxels::Entry& v, int i, int j, int k, Int3 start,
                                       const VolumeView& vb, bool inside, float (*p4)[4]) const {
  const Int3 w = window_;
  const std::size_t sy = static_cast<std::size_t>(vb.nx), sz = sy * static_cast<std::size_t>(vb.ny);
  const float wa = v.value * wx_[i] * wy_[j] * wz_[k];
  alignas(16) float px[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  float py[3], pz[3];
  int xs[3], ys[3], zs[3];
  // Per axis, which lags wrap: only (voxel, lag) pairs with a wrap are left here.
  const bool wrap_x[3] = {i == 0, false, i == w.x - 1}, wrap_y[3] = {j == 0, false, j == w.y - 1},
             wrap_z[3] = {k == 0, false, k == w.z - 1};
  for (int d = -1; d <= 1; ++d) {
    px[d + 1] = px_[i + d + 2];
    py[d + 1] = py_[j + d + 2];
    pz[d + 1] = pz_[k + d + 2];
    xs[d + 1] = start.x + wrap(i + d, w.x);
    ys[d + 1] = start.y + wrap(j + d, w.y);
    zs[d + 1] = start.z + wrap(k + d, w.z);
  }
  for (int dz = 0; dz < 3; ++dz)
    for (int dy = 0; dy < 3; ++dy) {
      const bool row_wraps = wrap_z[dz] || wrap_y[dy];
      if (!row_wraps && !wrap_x[0] && !wrap_x[2]) continue;
      const float f = wa * pz[dz] * py[dy];
      // (Inside: every wrapped lag is inside the volume, no bounds tests.)
      const bool row_in = inside || (zs[dz] >= 0 && zs[dz] < vb.nz && ys[dy] >= 0 && ys[dy] < vb.ny);
      const float* row = vb.data + (row_in ? static_cast<std::size_t>(zs[dz]) * sz + static_cast<std::size_t>(ys[dy]) * sy : 0);
      float* pr = p4[dy + 3 * dz];
      for (int dx = 0; dx < 3; ++dx)
        if (row_wraps || wrap_x[dx])
          pr[dx] += f * px[dx] * (row_in && (inside || (xs[dx] >= 0 && xs[dx] < vb.nx)) ? row[xs[dx]] : 0.0f);
    }
}

void DirectCorrelator::outer_lags(const OccupiedVoxels& oa, const VolumeView& vb, const OccupiedVoxels& ob, Int3 start,
                                  const int lags[][3], int count, double mean_a, double mean_b, double* out) const {
  const Int3 w = window_;
  double ps[3] = {}, qas[3] = {}, qbs[3] = {};
  auto for_entries = [&](const OccupiedVoxels& o, auto&& f) { for_each_in_window(o, start, w, f); };
  const bool inside = start.x >= 0 && start.y >= 0 && start.z >= 0 && start.x + w.x <= vb.nx &&
                      start.y + w.y <= vb.ny && start.z + w.z <= vb.nz;
  auto b_at = [&](int i, int j, int k) -> float {
    const int x = start.x + i, y = start.y + j, z = start.z + k;
    if (!inside && (x < 0 || y < 0 || z < 0 || x >= vb.nx || y >= vb.ny || z >= vb.nz)) return 0.0f;
    return vb.data[vb.linear(x, y, z)];
  };
  // As correlate()'s single lag: P and QA over a's entries, QB over b's, circular in the window.
  // The weights at the shifted positions come from the circularly padded tables (|lag| <= 2).
  for_entries(oa, [&](int i, int j, int k, float value) {
    const float wa = value * wx_[i] * wy_[j] * wz_[k];
    for (int o = 0; o < count; ++o) {
      const int di = i + lags[o][0], dj = j + lags[o][1], dk = k + lags[o][2];
      const float f = wa * px_[di + 2] * py_[dj + 2] * pz_[dk + 2];
      ps[o] += f * b_at(wrap(di, w.x), wrap(dj, w.y), wrap(dk, w.z));
      qas[o] += f;
    }
  });
  for_entries(ob, [&](int i, int j, int k, float value) {
    const float wb = wx_[i] * wy_[j] * wz_[k] * value;
    for (int o = 0; o < count; ++o)
      qbs[o] += static_cast<double>(wb) * px_[i - lags[o][0] + 2] * py_[j - lags[o][1] + 2] * pz_[k - lags[o][2] + 2];
  });
  for (int o = 0; o < count; ++o) {
    const double k = kx_[lags[o][0] + 2] * ky_[lags[o][1] + 2] * kz_[lags[o][2] + 2];
    out[o] = ps[o] - mean_b * qas[o] - mean_a * qbs[o] + mean_a * mean_b * k;
  }
}

}  // namespace tomorig::piv::detail
