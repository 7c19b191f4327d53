#pragma once
// Intensity against depth for reconstructions (thesis Fig. 3.10 and 5.9; issue 23 asked for it
// as a picture): the mean intensity per voxel of every z-slice, one curve per volume, with axes
// in mm and intensity. An 8-bit grey image, for storage::write_png.
#include <string>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/core/volume.h"

namespace tomorig::quality {

// Mean intensity per voxel of each z-slice k (the sum of its active voxels / nx / ny).
std::vector<double> mean_intensity_per_slice(const SparseVolume& volume);

struct DepthCurve {
  std::string label;            // "A", "B", ...
  std::vector<double> z_mm;     // slice centres
  std::vector<double> values;   // mean intensity per voxel
};

// Throws bad_input if there is no curve or a curve's arrays are empty or differ in length.
Image depth_profile_plot(const std::vector<DepthCurve>& curves, const std::string& title);

}  // namespace tomorig::quality
