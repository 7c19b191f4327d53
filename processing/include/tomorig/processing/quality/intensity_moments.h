#pragma once
// Where the intensity of a volume lies: its total, centroid and spread per axis. For the mean
// intensity volume of a spray (thesis Sect. 7.4, Fig. 7.12 right), whose mass marks where
// droplets appear frequently; the spray statistics judge it against the simulator's droplets.
#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::quality {

struct IntensityMoments {
  double mass = 0;        // sum of the voxel intensities (negative ones count as 0)
  float max = 0;          // brightest voxel
  Vec3d centroid_mm;      // intensity-weighted centre, world mm
  // Per axis, the world position below which `tail`, half and 1 - `tail` of the mass lie
  // (linear within a voxel): the plume's extent and median.
  Vec3d low_mm, median_mm, high_mm;
};

// Throws bad_input for tail outside (0, 0.5). An empty or all-zero volume gives mass 0 and the
// positions at the grid's origin.
IntensityMoments intensity_moments(const DenseVolume& volume, double tail = 0.05);

}  // namespace tomorig::quality
