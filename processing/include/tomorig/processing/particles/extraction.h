#pragma once
// Particles from reconstructed volumes (thesis Sect. 3.1.3 and 3.2.2): local maxima, 3-D
// segmentation into blobs, centre of mass, size and intensity.
//
// Segmentation is a watershed by steepest ascent: every voxel above `voxel_floor` points to
// its brightest 26-neighbour if that is brighter than itself, and so belongs to the local
// maximum its chain of pointers ends at. Touching particles therefore split along the valley
// between their peaks instead of merging into one component. Ties are broken by the linear
// index, so plateaus still have exactly one maximum and the result never depends on threads.
// A blob keeps only the voxels within `max_radius_voxel` (per axis) of its peak: the
// thesis's "given cluster size", which keeps a large low-level haze out of the centroid.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::particles {

struct ExtractionOptions {
  // Voxels at or below this value are background and never part of a blob. Raise it when a
  // reconstruction has a noise floor (MLOS); 0 suits MART-family output and truth volumes.
  float voxel_floor = 0.0f;
  // A local maximum becomes a particle only if its value is > max(peak_threshold,
  // relative_peak_threshold * brightest voxel of the volume). The relative default drops the
  // countless faint maxima that multiplicative algorithms leave in their ghost haze.
  float peak_threshold = 0.0f;
  double relative_peak_threshold = 0.01;
  int max_radius_voxel = 3;  // blob extent limit around its peak, per axis; 3 covers 4 sigma of a 3-voxel blob
  int threads = 0;           // OpenMP threads; 0: the OpenMP default. Never changes the result.

  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

// One blob. Voxel coordinates are continuous grid coordinates (voxel (i, j, k) centre at
// (i, j, k)); world = grid.centre_of(voxel).
struct Particle {
  Vec3d voxel;                       // intensity-weighted centre of mass
  Vec3d world;                       // the same in mm
  std::uint32_t peak_index = 0;      // linear index of the local maximum
  float peak = 0.0f;                 // value of the local maximum
  double integrated = 0.0;           // sum of the blob's voxel values
  int voxel_count = 0;               // voxels in the blob
  int min_i = 0, min_j = 0, min_k = 0;  // bounding box of the blob, inclusive
  int max_i = 0, max_j = 0, max_k = 0;
  double mean_intensity() const { return voxel_count > 0 ? integrated / voxel_count : 0.0; }
};

struct ExtractionReport {
  std::vector<Particle> particles;  // ordered by peak_index
  std::size_t active_voxels = 0;    // voxels above voxel_floor
  std::size_t local_maxima = 0;     // maxima before the peak threshold
  float peak_cutoff = 0.0f;         // the peak threshold actually applied
  double seconds = 0.0;
  std::string brief() const;
};

// Throws tomorig::Error (bad_input) on a malformed volume (index/intensity size mismatch,
// indices not ascending or outside the grid, a grid beyond 2^32 voxels) or bad options.
ExtractionReport extract_particles(const SparseVolume& volume, const ExtractionOptions& options = {});
ExtractionReport extract_particles(const DenseVolume& volume, const ExtractionOptions& options = {});

}  // namespace tomorig::particles
