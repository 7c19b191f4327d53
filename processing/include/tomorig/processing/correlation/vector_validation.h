#pragma once
// Validation of a displacement field (thesis Sect. 5.4.3, 7.5): minimum correlation peak,
// maximum displacement, illumination mask, and the normalised median test of Westerweel &
// Scarano (2005) with replacement by the neighbourhood median.
#include <cstdint>
#include <vector>

#include "tomorig/core/vector_field.h"
#include "tomorig/processing/correlation/correlation_options.h"

namespace tomorig::piv {

struct ValidationCounts {
  std::size_t low_peak = 0, too_large = 0, masked = 0, median_outliers = 0, replaced = 0;
};

// Rules, in order: a node with mask[n] == 0 (mask may be empty), or a peak below min_peak, is
// invalid; a vector above max_displacement or failing the median test (any component's
// normalised residual above the threshold, neighbours = valid nodes of the 3x3x3 block) is
// replaced by the component-wise median of its valid neighbours, or invalid if it has none.
// Every input status other than `invalid` is treated as a measured vector.
ValidationCounts validate_field(VectorField& field, const CorrelationOptions& options,
                                const std::vector<std::uint8_t>& mask = {});

}  // namespace tomorig::piv
