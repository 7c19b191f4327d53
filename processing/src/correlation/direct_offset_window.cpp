// DirectCorrelator::correlate_around: one window pair of a pass without deformation (the
// single pass, the integer-offset pass) by sparse direct correlation (direct_correlator.h) at
// the lags around a centre found by the binned pre-search (correlate.cpp): the 27 lags around
// it (and the peak's outer neighbours) replace the three 3-D FFTs of the window; where the peak
// lies beyond them the caller falls back to the FFT.
#include <chrono>
#include <cstdlib>

#include "correlation/direct_correlator.h"
#include "correlation/direct_peak.h"

namespace tomorig::piv::detail {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// The entries of `o` inside the window at `start` (window coordinates), into `out`.
void gather_window(const OccupiedVoxels& o, Int3 start, Int3 w, std::vector<OccupiedVoxels::Entry>& out) {
  out.clear();
  for_each_in_window(o, start, w, [&](int i, int j, int k, float value) {
    out.push_back({static_cast<std::uint16_t>(i), static_cast<std::uint16_t>(j), static_cast<std::uint16_t>(k), value});
  });
}

}  // namespace

WindowPeak DirectCorrelator::correlate_around(const OccupiedVoxels& oa, const OccupiedVoxels& ob, const VolumeView& vb,
                                              Int3 start_a, Int3 start_b, Int3 centre, Scratch& s,
                                              bool& fallback) const {
  constexpr int R = 1, L = 2 * R + 1, kLags = kDirectLags<R>;
  fallback = false;
  WindowPeak result;
  const auto t0 = Clock::now();
  const Int3 w = window_;
  // The lags searched must stay clear of the wrap's other side (the FFT's plane holds lags
  // -W/2 .. W/2 - 1 per axis).
  if (std::abs(centre.x) + R + 1 > w.x / 2 - 1 || std::abs(centre.y) + R + 1 > w.y / 2 - 1 ||
      std::abs(centre.z) + R + 1 > w.z / 2 - 1) {
    fallback = true;
    return result;
  }
  gather_window(oa, start_a, w, s.window_a);
  gather_window(ob, start_b, w, s.window_b);
  auto at = [](const std::vector<float>& axis, int i) {  // axis weight at i, circular
    const int n = static_cast<int>(axis.size());
    return axis[((i % n) + n) % n];
  };
  auto wrapped = [](int i, int n) { return ((i % n) + n) % n; };
  // Per axis, for window coordinates i = -2 .. W + 1 at index i + 2: the weight at i + c and at
  // i - c (circular), and b's volume coordinate of window position i + c (circular): table
  // look-ups in the entry loops instead of a modulo per lag.
  auto tables = [&](Scratch::AxisTables& t, const std::vector<float>& axis, int c, int start) {
    const int n = static_cast<int>(axis.size());
    t.plus.resize(n + 4);
    t.minus.resize(n + 4);
    t.b.resize(n + 4);
    for (int i = -2; i < n + 2; ++i) {
      t.plus[i + 2] = at(axis, i + c);
      t.minus[i + 2] = at(axis, i - c);
      t.b[i + 2] = start + wrapped(i + c, n);
    }
  };
  tables(s.axes[0], wx_, centre.x, start_b.x);
  tables(s.axes[1], wy_, centre.y, start_b.y);
  tables(s.axes[2], wz_, centre.z, start_b.z);
  const float *plus_x = s.axes[0].plus.data() + 2, *plus_y = s.axes[1].plus.data() + 2, *plus_z = s.axes[2].plus.data() + 2;
  const float *minus_x = s.axes[0].minus.data() + 2, *minus_y = s.axes[1].minus.data() + 2,
              *minus_z = s.axes[2].minus.data() + 2;
  const int *b_x = s.axes[0].b.data() + 2, *b_y = s.axes[1].b.data() + 2, *b_z = s.axes[2].b.data() + 2;

  // Means and energies (Eq. 2.16) as the FFT path computes them, over the listed voxels.
  double sum_a = 0, w2a = 0, w2a2 = 0, sum_b = 0, w2b = 0, w2b2 = 0;
  for (const auto& e : s.window_a) {
    const double ww = static_cast<double>(wx_[e.x]) * wy_[e.y] * wz_[e.z], v = e.value;
    sum_a += v;
    w2a += ww * ww * v;
    w2a2 += ww * ww * v * v;
  }
  // QB(s) = sum w(y) B(y) w(y (-) s), circular: separable per entry.
  float qb[kLags] = {};
  for (const auto& e : s.window_b) {
    const double ww = static_cast<double>(wx_[e.x]) * wy_[e.y] * wz_[e.z], v = e.value;
    sum_b += v;
    w2b += ww * ww * v;
    w2b2 += ww * ww * v * v;
    const float wb = static_cast<float>(ww * v);
    float xs[L], ys[L], zs[L];
    for (int d = -R; d <= R; ++d) {
      xs[d + R] = minus_x[e.x - d];
      ys[d + R] = minus_y[e.y - d];
      zs[d + R] = minus_z[e.z - d];
    }
    for (int dz = 0; dz < L; ++dz)
      for (int dy = 0; dy < L; ++dy) {
        const float f = wb * zs[dz] * ys[dy];
        float* q = qb + L * (dy + L * dz);
        for (int dx = 0; dx < L; ++dx) q[dx] += f * xs[dx];
      }
  }
  const double n = static_cast<double>(w.x) * w.y * w.z;
  const double mean_a = sum_a / n, mean_b = sum_b / n;
  const double energy_a = w2a2 - 2 * mean_a * w2a + mean_a * mean_a * weight_energy_;
  const double energy_b = w2b2 - 2 * mean_b * w2b + mean_b * mean_b * weight_energy_;
  const auto t1 = Clock::now();
  s.seconds.load += seconds_between(t0, t1);
  if (!(energy_a > 1e-20) || !(energy_b > 1e-20)) {
    result.empty = true;
    return result;
  }

  // P(s) = sum w(x) A(x) w(x (+) s) B(x (+) s) and QA(s) = sum w(x) A(x) w(x (+) s), circular in
  // the window, b read dense at its window's start.
  const bool inside = start_b.x >= 0 && start_b.y >= 0 && start_b.z >= 0 && start_b.x + w.x <= vb.nx &&
                      start_b.y + w.y <= vb.ny && start_b.z + w.z <= vb.nz;
  const std::size_t sy = static_cast<std::size_t>(vb.nx), sz = sy * static_cast<std::size_t>(vb.ny);
  float p[kLags] = {}, qa[kLags] = {};
  for (const auto& e : s.window_a) {
    const float wa = e.value * wx_[e.x] * wy_[e.y] * wz_[e.z];
    float xw[L], yw[L], zw[L];
    int xi[L], yi[L], zi[L];
    for (int d = -R; d <= R; ++d) {
      xw[d + R] = plus_x[e.x + d];
      yw[d + R] = plus_y[e.y + d];
      zw[d + R] = plus_z[e.z + d];
      xi[d + R] = b_x[e.x + d];
      yi[d + R] = b_y[e.y + d];
      zi[d + R] = b_z[e.z + d];
    }
    // Where no lag of a row wraps and b holds the row, its three lags are contiguous in b.
    const bool x_plain = inside && xi[L - 1] - xi[0] == L - 1;
    for (int dz = 0; dz < L; ++dz)
      for (int dy = 0; dy < L; ++dy) {
        const float f = wa * zw[dz] * yw[dy];
        float* pr = p + L * (dy + L * dz);
        float* qr = qa + L * (dy + L * dz);
        const bool row_in = inside || (zi[dz] >= 0 && zi[dz] < vb.nz && yi[dy] >= 0 && yi[dy] < vb.ny);
        const float* row = vb.data + (row_in ? static_cast<std::size_t>(zi[dz]) * sz + static_cast<std::size_t>(yi[dy]) * sy : 0);
        if (x_plain) {
          const float* b = row + xi[0];
          for (int dx = 0; dx < L; ++dx) {
            const float g = f * xw[dx];
            qr[dx] += g;
            pr[dx] += g * b[dx];
          }
          continue;
        }
        for (int dx = 0; dx < L; ++dx) {
          const float g = f * xw[dx];
          qr[dx] += g;
          if (row_in && (inside || (xi[dx] >= 0 && xi[dx] < vb.nx))) pr[dx] += g * row[xi[dx]];
        }
      }
  }
  auto k_at = [&](int sx, int sy_, int sz_) {
    return static_cast<double>(kx_full_[wrapped(sx, w.x)]) * ky_full_[wrapped(sy_, w.y)] * kz_full_[wrapped(sz_, w.z)];
  };
  double r[kLags];
  for (int dz = -R; dz <= R; ++dz)
    for (int dy = -R; dy <= R; ++dy)
      for (int dx = -R; dx <= R; ++dx) {
        const int l = direct_lag_index<R>(dx, dy, dz);
        r[l] = p[l] - mean_b * qa[l] - mean_a * qb[l] + mean_a * mean_b * k_at(centre.x + dx, centre.y + dy, centre.z + dz);
      }
  const auto t2 = Clock::now();
  s.seconds.correlation += seconds_between(t1, t2);

  // The outer neighbours (relative lags +-2), from the same entries and the same tables (they
  // cover window positions -2 .. W + 1 around the centre).
  auto outer = [&](const int (*lags)[3], int count, double* out) {
    double ps[3] = {}, qas[3] = {}, qbs[3] = {};
    auto b_at = [&](int x, int y, int z) -> float {
      if (!inside && (x < 0 || y < 0 || z < 0 || x >= vb.nx || y >= vb.ny || z >= vb.nz)) return 0.0f;
      return vb.data[vb.linear(x, y, z)];
    };
    for (const auto& e : s.window_a) {
      const float wa = e.value * wx_[e.x] * wy_[e.y] * wz_[e.z];
      for (int o = 0; o < count; ++o) {
        const int di = e.x + lags[o][0], dj = e.y + lags[o][1], dk = e.z + lags[o][2];
        const float f = wa * plus_x[di] * plus_y[dj] * plus_z[dk];
        ps[o] += f * b_at(b_x[di], b_y[dj], b_z[dk]);
        qas[o] += f;
      }
    }
    for (const auto& e : s.window_b) {
      const float wb = wx_[e.x] * wy_[e.y] * wz_[e.z] * e.value;
      for (int o = 0; o < count; ++o)
        qbs[o] += static_cast<double>(wb) * minus_x[e.x - lags[o][0]] * minus_y[e.y - lags[o][1]] *
                  minus_z[e.z - lags[o][2]];
    }
    for (int o = 0; o < count; ++o)
      out[o] = ps[o] - mean_b * qas[o] - mean_a * qbs[o] +
               mean_a * mean_b * k_at(centre.x + lags[o][0], centre.y + lags[o][1], centre.z + lags[o][2]);
  };
  result = direct_peak<R>(r, energy_a, energy_b, outer, fallback);
  result.dx += static_cast<float>(centre.x);
  result.dy += static_cast<float>(centre.y);
  result.dz += static_cast<float>(centre.z);
  s.seconds.peak += seconds_between(t2, Clock::now());
  return result;
}

}  // namespace tomorig::piv::detail
