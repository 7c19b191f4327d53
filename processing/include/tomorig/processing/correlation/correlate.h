#pragma once
// 3-D FFT cross-correlation of two volumes into a validated displacement field (thesis
// Sect. 2.5, 5.4.3). Displacements are in voxels of the input grid, from volume a to b; the
// field's origin and spacing are in world mm (node centres of the final pass's windows).
#include <cstddef>
#include <vector>

#include "tomorig/core/vector_field.h"
#include "tomorig/core/volume.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv {

struct PassReport {
  int nodes_x = 0, nodes_y = 0, nodes_z = 0;
  std::size_t low_peak = 0;          // below min_peak
  std::size_t too_large = 0;         // above max_displacement
  std::size_t median_outliers = 0;   // failed the normalised median test
  std::size_t replaced = 0;
  std::size_t masked = 0;            // below the illumination threshold
  std::size_t peak_fallbacks = 0;    // axes fitted by the fallback instead of the 3-point Gaussian
  std::size_t empty_windows = 0;     // windows without contrast, skipped before any correlation
  const char* method = "fft";        // how the windows were correlated: "fft" or "direct"
  std::size_t fft_fallbacks = 0;     // direct pass: windows whose peak lay beyond lag +-1, done by FFT
  double occupied_fraction = 0.0;    // deformation pass: voxels of the deformed pair above the
                                     // occupancy threshold (the direct/FFT choice), else 0
  // Time breakdown (wall seconds of the pass's stages, on the calling thread):
  double seconds = 0.0;              // the whole pass
  double seconds_deformation = 0.0;  // binning, B-spline prefilter and volume deformation
  double seconds_windows = 0.0;      // the parallel loop over the windows (load, correlate, peak)
  double seconds_validation = 0.0;   // mask, validation, predictor for the next pass
  // The window loop split by stage, in thread-seconds summed over the threads (each stage's
  // share of seconds_windows is its share of these).
  double thread_seconds_load = 0.0;         // copying windows, means, energies, weights; or listing the occupied voxels (wall x threads)
  double thread_seconds_correlation = 0.0;  // FFTs and spectrum product, or direct sums
  double thread_seconds_peak = 0.0;         // highest value and sub-voxel fit
};

struct CorrelationReport {
  std::vector<PassReport> passes;
  double seconds_total = 0.0;
  double valid_fraction() const;     // of the final field: status valid
  std::size_t valid = 0, replaced = 0, invalid = 0;
};

// Throws tomorig::Error (bad_input) for volumes on different grids or invalid options.
VectorField correlate(const DenseVolume& a, const DenseVolume& b, const CorrelationOptions& options,
                      CorrelationReport& report);
VectorField correlate(const SparseVolume& a, const SparseVolume& b, const CorrelationOptions& options,
                      CorrelationReport& report);

// The FFT floor of a correlation: the time of the FFTs alone (two forward, one inverse per
// window, on buffers already in cache, no loading, no peak search) for every window of every
// pass `options` would correlate on `grid`, with the same threads and plans. Measured, so call
// it in the same run as the correlation it is compared with.
struct FftFloor {
  std::vector<double> pass_seconds;
  double seconds_total = 0.0;
};
FftFloor measure_fft_floor(const VoxelGrid& grid, const CorrelationOptions& options);

}  // namespace tomorig::piv
