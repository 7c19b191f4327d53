#include "correlation/fft_correlator.h"

#include <fftw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <numbers>
#include <tuple>

#include "tomorig/core/error.h"
#include "correlation/window_kernels.h"
#include "tomorig/processing/correlation/peak_fit.h"

namespace tomorig::piv::detail {
namespace {

struct PlanPair {
  fftwf_plan forward = nullptr;   // r2c
  fftwf_plan backward = nullptr;  // c2r
};

// FFTW's planner is not thread-safe; plan execution with the new-array functions is. Plans
// live for the process, one pair per window size, like FFTW's own wisdom.
std::mutex& planner_mutex() {
  static std::mutex mutex;
  return mutex;
}

const PlanPair& plans_for(Int3 w) {
  static std::map<std::tuple<int, int, int>, PlanPair> cache;
  std::lock_guard lock(planner_mutex());
  auto [it, inserted] = cache.try_emplace({w.x, w.y, w.z});
  if (inserted) {
    const std::size_t real = static_cast<std::size_t>(w.x) * w.y * w.z;
    const std::size_t complex = static_cast<std::size_t>(w.x / 2 + 1) * w.y * w.z;
    std::unique_ptr<float, FftwFree> r(fftwf_alloc_real(real));
    std::unique_ptr<float, FftwFree> c(reinterpret_cast<float*>(fftwf_alloc_complex(complex)));
    auto* cc = reinterpret_cast<fftwf_complex*>(c.get());
    // FFTW takes dimensions slowest first: z, y, x. FFTW_ESTIMATE, not FFTW_MEASURE: a measured
    // plan is chosen by timing, so two processes (MPI ranks, a resumed run, a busy machine) could
    // pick different algorithms and round differently; an estimated plan is the same everywhere,
    // so a set's vectors are bit-identical whichever process correlates it.
    it->second.forward = fftwf_plan_dft_r2c_3d(w.z, w.y, w.x, r.get(), cc, FFTW_ESTIMATE);
    it->second.backward = fftwf_plan_dft_c2r_3d(w.z, w.y, w.x, cc, r.get(), FFTW_ESTIMATE);
    if (!it->second.forward || !it->second.backward) {
      cache.erase(it);
      throw runtime_error("correlation: FFTW could not plan a window of " + std::to_string(w.x) + " x " +
                          std::to_string(w.y) + " x " + std::to_string(w.z));
    }
  }
  return it->second;
}

int signed_lag(int index, int size) { return index < size / 2 ? index : index - size; }

using Clock = std::chrono::steady_clock;
double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

}  // namespace

void FftwFree::operator()(void* p) const { fftwf_free(p); }

std::vector<float> axis_weights(int n, WindowWeighting weighting, double gaussian_sigma) {
  std::vector<float> w(n, 1.0f);
  const double centre = 0.5 * (n - 1);
  for (int i = 0; i < n; ++i) {
    const double u = (i - centre) / n;  // -0.5 .. 0.5
    if (weighting == WindowWeighting::gaussian)
      w[i] = static_cast<float>(std::exp(-0.5 * (u / gaussian_sigma) * (u / gaussian_sigma)));
    if (weighting == WindowWeighting::hann)
      w[i] = static_cast<float>(0.5 + 0.5 * std::cos(2.0 * std::numbers::pi * (i + 0.5 - 0.5 * n) / n));
  }
  return w;
}


FftCorrelator::FftCorrelator(Int3 window, WindowWeighting weighting, double gaussian_sigma)
    : window_(window),
      real_count_(static_cast<std::size_t>(window.x) * window.y * window.z),
      complex_count_(static_cast<std::size_t>(window.x / 2 + 1) * window.y * window.z) {
  plans_ = &plans_for(window);
  if (weighting != WindowWeighting::top_hat) {
    const auto wx = axis_weights(window.x, weighting, gaussian_sigma),
               wy = axis_weights(window.y, weighting, gaussian_sigma),
               wz = axis_weights(window.z, weighting, gaussian_sigma);
    weights_.resize(real_count_);
    std::size_t n = 0;
    for (int k = 0; k < window.z; ++k)
      for (int j = 0; j < window.y; ++j)
        for (int i = 0; i < window.x; ++i) weights_[n++] = wx[i] * wy[j] * wz[k];
  }
}

FftCorrelator::Scratch FftCorrelator::make_scratch() const {
  Scratch s;
  s.a.reset(fftwf_alloc_real(real_count_));
  s.b.reset(fftwf_alloc_real(real_count_));
  s.spectrum_a.reset(reinterpret_cast<float*>(fftwf_alloc_complex(complex_count_)));
  s.spectrum_b.reset(reinterpret_cast<float*>(fftwf_alloc_complex(complex_count_)));
  if (!s.a || !s.b || !s.spectrum_a || !s.spectrum_b) throw runtime_error("correlation: out of memory for FFT buffers");
  return s;
}

double FftCorrelator::load_window(const VolumeView& v, Int3 start, float* out) const {
  // Rows are copied whole and summed with several float lanes (omp simd): a single serial
  // float or double accumulator is a latency chain of 4 cycles per voxel, which cost more
  // than the FFTs themselves. Each row's float sum goes into a double.
  const int x0 = std::max(0, start.x), x1 = std::min(v.nx, start.x + window_.x);
  double sum = 0.0;
  std::size_t n = 0;
  for (int k = 0; k < window_.z; ++k) {
    const int z = start.z + k;
    for (int j = 0; j < window_.y; ++j, n += window_.x) {
      const int y = start.y + j;
      float* row = out + n;
      if (z < 0 || z >= v.nz || y < 0 || y >= v.ny || x0 >= x1) {
        std::fill(row, row + window_.x, 0.0f);
        continue;
      }
      const float* src = v.data + v.linear(0, y, z);
      std::fill(row, row + (x0 - start.x), 0.0f);
      std::copy(src + x0, src + x1, row + (x0 - start.x));
      std::fill(row + (x1 - start.x), row + window_.x, 0.0f);
      float row_sum = 0.0f;
#pragma omp simd reduction(+ : row_sum)
      for (int x = x0; x < x1; ++x) row_sum += src[x];
      sum += row_sum;
    }
  }
  const float mean = static_cast<float>(sum / static_cast<double>(real_count_));
  // Energy per x-y slice in float lanes, slices summed in double.
  const std::size_t slice = static_cast<std::size_t>(window_.x) * window_.y;
  double energy = 0.0;
  for (std::size_t base = 0; base < real_count_; base += slice) {
    float* o = out + base;
    float slice_energy = 0.0f;
    if (weights_.empty()) {
#pragma omp simd reduction(+ : slice_energy)
      for (std::size_t m = 0; m < slice; ++m) {
        o[m] -= mean;
        slice_energy += o[m] * o[m];
      }
    } else {
      const float* w = weights_.data() + base;
#pragma omp simd reduction(+ : slice_energy)
      for (std::size_t m = 0; m < slice; ++m) {
        o[m] = (o[m] - mean) * w[m];
        slice_energy += o[m] * o[m];
      }
    }
    energy += slice_energy;
  }
  return energy;
}

WindowPeak FftCorrelator::correlate(const VolumeView& va, Int3 start_a, const VolumeView& vb, Int3 start_b,
                                    Scratch& s) const {
  WindowPeak result;
  const auto t0 = Clock::now();
  const double energy_a = load_window(va, start_a, s.a.get());
  const double energy_b = load_window(vb, start_b, s.b.get());
  const auto t1 = Clock::now();
  s.seconds.load += seconds_between(t0, t1);
  // A window without contrast has no defined correlation coefficient (Eq. 2.16 divides by 0).
  if (!(energy_a > 1e-20) || !(energy_b > 1e-20)) {
    result.empty = true;
    return result;
  }

  const auto& plans = *static_cast<const PlanPair*>(plans_);
  auto* fa = reinterpret_cast<fftwf_complex*>(s.spectrum_a.get());
  auto* fb = reinterpret_cast<fftwf_complex*>(s.spectrum_b.get());
  fftwf_execute_dft_r2c(plans.forward, s.a.get(), fa);
  fftwf_execute_dft_r2c(plans.forward, s.b.get(), fb);
  // conj(A) * B: the correlation peaks at the displacement of b relative to a.
  spectrum_product(s.spectrum_a.get(), s.spectrum_b.get(), complex_count_);
  float* plane = s.a.get();
  fftwf_execute_dft_c2r(plans.backward, fa, plane);
  const auto t2 = Clock::now();
  s.seconds.correlation += seconds_between(t1, t2);
  struct PeakClock {  // charges the peak search and fit, whichever return is taken
    Clock::time_point start;
    double& sum;
    ~PeakClock() { sum += seconds_between(start, Clock::now()); }
  } peak_clock{t2, s.seconds.peak};

  // The first highest value.
  const std::size_t best = first_maximum(plane, real_count_);
  if (best >= real_count_) return result;  // NaN in the plane: no peak
  const float best_value = plane[best];
  // FFTW's inverse is unnormalised (factor N); Eq. 2.16 divides by the standard deviations.
  const double scale = 1.0 / (static_cast<double>(real_count_) * std::sqrt(energy_a * energy_b));
  const int ix = static_cast<int>(best % window_.x);
  const int iy = static_cast<int>((best / window_.x) % window_.y);
  const int iz = static_cast<int>(best / (static_cast<std::size_t>(window_.x) * window_.y));
  auto at = [&](int x, int y, int z) {
    x = (x + window_.x) % window_.x;
    y = (y + window_.y) % window_.y;
    z = (z + window_.z) % window_.z;
    return static_cast<double>(plane[x + static_cast<std::size_t>(window_.x) * (y + static_cast<std::size_t>(window_.y) * z)]);
  };
  const double centre = best_value;
  auto fit_axis = [&](int index, int size, double left, double right) {
    const int lag = signed_lag(index, size);
    // The lowest and highest lags border the periodic wrap: their outer neighbour is the
    // opposite end of the plane, not a neighbouring displacement.
    const bool has_left = lag > size / 2 - size, has_right = lag < size / 2 - 1;
    const PeakFit1d fit = fit_peak_1d(left, centre, right, has_left, has_right);
    if (fit.method != PeakFitMethod::gaussian) ++result.fallbacks;
    return lag + fit.offset;
  };
  result.dx = static_cast<float>(fit_axis(ix, window_.x, at(ix - 1, iy, iz), at(ix + 1, iy, iz)));
  result.dy = static_cast<float>(fit_axis(iy, window_.y, at(ix, iy - 1, iz), at(ix, iy + 1, iz)));
  result.dz = static_cast<float>(fit_axis(iz, window_.z, at(ix, iy, iz - 1), at(ix, iy, iz + 1)));
  result.peak = static_cast<float>(centre * scale);
  result.valid = true;
  return result;
}

void FftCorrelator::transforms_only(Scratch& s) const {
  const auto& plans = *static_cast<const PlanPair*>(plans_);
  auto* fa = reinterpret_cast<fftwf_complex*>(s.spectrum_a.get());
  auto* fb = reinterpret_cast<fftwf_complex*>(s.spectrum_b.get());
  fftwf_execute_dft_r2c(plans.forward, s.a.get(), fa);
  fftwf_execute_dft_r2c(plans.forward, s.b.get(), fb);
  // Into spectrum_b's memory (large enough): a and b stay the inputs of every repetition.
  fftwf_execute_dft_c2r(plans.backward, fa, s.spectrum_b.get());
}

}  // namespace tomorig::piv::detail
