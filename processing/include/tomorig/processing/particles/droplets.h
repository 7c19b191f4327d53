#pragma once
// Droplets in volumes reconstructed from inverted shadow images (tomographic shadowgraphy,
// thesis Ch. 6-7, issue 20): 3-D blobs (extract_particles' watershed) with their position, peak
// intensity (the thesis's rough size indicator) and an equivalent diameter from the blob's
// cross-section. The views of a shadowgraphy rig are yawed about y, so a blob is elongated
// along z (depth); its x-y cross-section through the peak is what follows the droplet's size.
//
//   auto drops = particles::detect_droplets(volume.to_dense(), {});
//   for (const auto& d : drops) fmt::print("{} {} {}\n", d.world.x, d.world.y, d.d_eq_um);
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::particles {

struct DropletDetectionOptions {
  // A blob's peak must exceed this fraction of the volume's brightest voxel: drops the faint
  // maxima of the ghost haze and of droplets below the visibility limit.
  double relative_peak_threshold = 0.05;
  int max_radius_voxel = 4;  // blob extent around its peak, per axis
  int threads = 0;           // OpenMP threads; 0: the default. Never changes the result.

  void validate() const;  // bad_input naming the field
};

struct DetectedDroplet {
  Vec3d world;            // intensity-weighted centre, mm
  float peak = 0.0f;      // brightest voxel
  double integrated = 0;  // sum of the blob's voxels
  // 2 sqrt(A / pi) of the area A of the voxels >= half the peak in the x-y slice through the
  // peak (within max_radius_voxel of it), mm. Includes the PSF's blur: an upper estimate for
  // droplets smaller than the PSF half-width.
  double d_eq_mm = 0;
};

std::vector<DetectedDroplet> detect_droplets(const DenseVolume& volume, const DropletDetectionOptions& options = {});

}  // namespace tomorig::particles
