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
  double seconds = 0.0;
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

}  // namespace tomorig::piv
