#pragma once
// Position accuracy of detected particles (thesis Sect. 3.2.2 and 3.3.3): a detection is true
// when its centre lies within the "radial distance of 1.5 x 1.5 x 1.8 voxel" of a known
// position, read here as the axis-aligned ellipsoid with those semi-axes (radii):
//   (dx / 1.5)^2 + (dy / 1.5)^2 + (dz / 1.8)^2 <= 1.
// Pairs are made one-to-one, closest first (in that normalised distance), so neither two
// detections of one particle nor one detection of two particles count twice.
#include <cstddef>
#include <span>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::quality {

struct MatchOptions {
  Vec3d radius_voxel{1.5, 1.5, 1.8};  // semi-axes of the acceptance ellipsoid
  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

struct PositionMatch {
  std::size_t true_particles = 0;   // true particles whose centre lies inside the grid
  std::size_t detections = 0;
  std::size_t matched = 0;          // true detections (one-to-one pairs)
  double detected_fraction = 0.0;   // matched / true_particles (0 if there are none)
  Vec3d rms_voxel;                  // RMS of detected - true per axis over the pairs
  Vec3d mean_voxel;                 // mean of detected - true per axis (bias)
  std::vector<std::size_t> truth_of_detection;  // per detection: the true particle, or npos
  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
};

// Both lists in continuous voxel coordinates of `grid` (voxel (i, j, k) centre at (i, j, k)).
// True particles outside [-0.5, n - 0.5) on any axis are left out (the grid cannot see them).
PositionMatch match_positions(std::span<const Vec3d> detected_voxel, std::span<const Vec3d> truth_voxel,
                              const VoxelGrid& grid, const MatchOptions& options = {});

}  // namespace tomorig::quality
