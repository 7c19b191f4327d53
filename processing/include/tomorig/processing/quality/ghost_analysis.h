#pragma once
// Ghost versus true blobs (thesis Sect. 3.2.2 and 3.3.2, Fig. 3.8, 3.9 and 3.11).
//
// The thesis masks the reconstruction with ellipsoids (3 x 3 x 4.5 voxel) around the true
// particles and labels connected components of the true and ghost parts. Masking voxel by
// voxel would, however, cut the tails of every true blob beyond 1.5 voxel (2 sigma, still
// 13 % of the peak) into rings of "ghosts", so even the ground truth itself would score
// ghosts. Here whole blobs (the watershed blobs of particles/extraction.h) are classified by
// where their peak lies: inside the mask, a true blob; outside, a ghost. A ghost fused to a
// true particle still counts as long as it has its own maximum.
#include <cstddef>
#include <span>

#include "tomorig/processing/particles/extraction.h"
#include "tomorig/processing/quality/ellipsoid_mask.h"

namespace tomorig::quality {

struct GhostAnalysis {
  std::size_t true_blobs = 0;
  std::size_t ghost_blobs = 0;
  double true_mean_intensity = 0.0;   // mean over true blobs of their mean intensity per voxel
  double ghost_mean_intensity = 0.0;  // the same over ghost blobs
  double ghost_true_count_ratio = 0.0;      // ghost_blobs / true_blobs; 0 without ghosts, +inf without true blobs
  double true_ghost_intensity_ratio = 0.0;  // true / ghost mean intensity; +inf without ghosts, 0 without true blobs
};

GhostAnalysis classify_blobs(std::span<const particles::Particle> blobs, const EllipsoidMask& mask);

}  // namespace tomorig::quality
