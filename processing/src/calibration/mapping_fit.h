#pragma once
// Least-squares fits of the mappings of polynomial_maps.h to normalised point pairs, by
// Levenberg-Marquardt on the output-space residual (Eq. A.3 in normalised units).
#include <vector>

#include "levenberg_marquardt.h"
#include "polynomial_maps.h"

namespace tomorig::calibration::detail {

struct MapFit {
  std::vector<double> coefficients;  // coefficient_count() values
  LmResult lm;
};

// LM from `initial` (coefficient_count() values; for a rational form the denominator's
// constant, the last value, is held at its initial value, normally 1).
MapFit fit_map(const MapForm& form, const MapSamples& samples, std::vector<double> initial, const LmSettings& settings);

// Linear start for a rational form: minimises the algebraic error N_i(x) - y_i D(x) with the
// denominator constant fixed to 1. Exact when the data lie on such a mapping.
std::vector<double> algebraic_rational_start(const MapForm& form, const MapSamples& samples);

}  // namespace tomorig::calibration::detail
