#pragma once
// FFT cross-correlation of two interrogation volumes normalised to the correlation coefficient
// of thesis Eq. 2.16, with a sub-voxel peak fit. FFTW plans are made once per window size
// (process-wide, under a mutex); each thread owns a Scratch, so no window allocates.
#include <cstddef>
#include <memory>
#include <vector>

#include "correlation/volume_view.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv::detail {

struct FftwFree {
  void operator()(void* p) const;
};

struct WindowPeak {
  float dx = 0, dy = 0, dz = 0;  // voxels from window a to window b (sub-voxel)
  float peak = 0;                // correlation coefficient at the integer peak
  int fallbacks = 0;             // axes not fitted by the 3-point Gaussian
  bool valid = false;            // false if a window has no contrast (zero variance)
  bool empty = false;            // no contrast: skipped before correlating
};

// Thread-seconds of one thread's windows, by stage (PassReport's breakdown).
struct StageSeconds {
  double load = 0, correlation = 0, peak = 0;
};

// The weights of one axis of a window (the window's weights are the product of the three).
std::vector<float> axis_weights(int n, WindowWeighting weighting, double gaussian_sigma);

class FftCorrelator {
 public:
  // gaussian_sigma: the Gaussian weighting's standard deviation as a fraction of the window
  // edge (ignored by the other weightings).
  FftCorrelator(Int3 window, WindowWeighting weighting, double gaussian_sigma = 0.25);

  struct Scratch {
    std::unique_ptr<float, FftwFree> a, b;
    std::unique_ptr<float, FftwFree> spectrum_a, spectrum_b;  // interleaved complex
    StageSeconds seconds;                                      // accumulated by correlate()
  };
  Scratch make_scratch() const;

  // Correlates the window of `va` starting at `start_a` with that of `vb` at `start_b`;
  // voxels outside a volume count as 0.
  WindowPeak correlate(const VolumeView& va, Int3 start_a, const VolumeView& vb, Int3 start_b, Scratch& scratch) const;

  // The FFTs of one window pair alone (two forward, one inverse) on the scratch buffers as they
  // are: the floor figure of measure_fft_floor.
  void transforms_only(Scratch& scratch) const;

 private:
  // Copies the window into `out`, subtracts its mean and applies the weights; returns sum(out^2).
  double load_window(const VolumeView& v, Int3 start, float* out) const;

  Int3 window_;
  std::size_t real_count_ = 0, complex_count_ = 0;
  std::vector<float> weights_;  // empty for a top hat
  const void* plans_ = nullptr; // the cached plan pair for this size
};

}  // namespace tomorig::piv::detail
