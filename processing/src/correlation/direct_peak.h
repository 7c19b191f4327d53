#pragma once
// The peak of a direct correlation (direct_correlator.h): the largest of the coefficients at
// lags -R..R, its outer neighbours at +-(R + 1) where the peak sits on the face of that cube,
// and the 3-point Gaussian fit per axis. Shared by the deformation passes' windows (R = 1, from
// their contracted sums) and the integer-offset pass's windows (R = 2, from their own entries).
#include <cmath>

#include "correlation/fft_correlator.h"
#include "tomorig/processing/correlation/peak_fit.h"

namespace tomorig::piv::detail {

template <int R = 1>
constexpr int direct_lag_index(int dx, int dy, int dz) {
  constexpr int n = 2 * R + 1;
  return (dx + R) + n * ((dy + R) + n * (dz + R));
}
template <int R>
inline constexpr int kDirectLags = (2 * R + 1) * (2 * R + 1) * (2 * R + 1);

// r: R(s) of Eq. 2.16 at the lags -R..R (direct_lag_index<R>). outer_lags(lags, count, out)
// evaluates up to 3 lags with one component +-(R + 1). `fallback` is set when the peak
// continues beyond the lags searched (the caller then correlates the window by FFT).
template <int R, class OuterLags>
WindowPeak direct_peak(const double (&r)[kDirectLags<R>], double energy_a, double energy_b, OuterLags&& outer_lags,
                       bool& fallback) {
  constexpr int n = 2 * R + 1;
  WindowPeak result;
  int best = 0;
  for (int l = 1; l < kDirectLags<R>; ++l)
    if (r[l] > r[best]) best = l;
  const int m[3] = {best % n - R, (best / n) % n - R, best / (n * n) - R};
  const double centre = r[best];
  double left[3], right[3];
  // The outer neighbours beyond the lags searched (one per axis whose peak lag is +-R),
  // evaluated together.
  int outer[3][3];
  int outer_axis[3];
  int outer_count = 0;
  for (int axis = 0; axis < 3; ++axis) {
    int lo[3] = {m[0], m[1], m[2]}, hi[3] = {m[0], m[1], m[2]};
    lo[axis] -= 1;
    hi[axis] += 1;
    if (lo[axis] >= -R) left[axis] = r[direct_lag_index<R>(lo[0], lo[1], lo[2])];
    if (hi[axis] <= R) right[axis] = r[direct_lag_index<R>(hi[0], hi[1], hi[2])];
    if (lo[axis] < -R || hi[axis] > R) {
      const int* lag = lo[axis] < -R ? lo : hi;
      outer[outer_count][0] = lag[0];
      outer[outer_count][1] = lag[1];
      outer[outer_count][2] = lag[2];
      outer_axis[outer_count++] = axis;
    }
  }
  if (outer_count > 0) {
    double values[3];
    outer_lags(outer, outer_count, values);
    for (int o = 0; o < outer_count; ++o) {
      const int axis = outer_axis[o];
      (outer[o][axis] < m[axis] ? left : right)[axis] = values[o];
    }
  }
  for (int axis = 0; axis < 3; ++axis)
    if (left[axis] > centre || right[axis] > centre) {  // the peak continues beyond: FFT
      fallback = true;
      return result;
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
  return result;
}

}  // namespace tomorig::piv::detail
