#pragma once
// One entry point for every quality metric of a reconstruction against simulator truth
// (thesis Sect. 3.2.2; docs/quality-metrics.md): Q global and windowed, ghost versus true
// blobs, position accuracy and detected fraction, intensity versus depth and the RSNR.
//
// QualityEvaluator does the work that depends only on the truth (truth volume, mask) once, so
// a benchmark loop over iterations or algorithms pays for it once:
//   tomorig::quality::QualityEvaluator judge(grid, true_particles_mm);
//   for (...) { QualityReport r = judge.evaluate(volume); ... r.q_global ... }
#include <array>
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"
#include "tomorig/processing/particles/extraction.h"
#include "tomorig/processing/quality/depth_profile.h"
#include "tomorig/processing/quality/gaussian_blobs.h"
#include "tomorig/processing/quality/quality_factor.h"

namespace tomorig::quality {

struct QualityOptions {
  GaussianBlobOptions truth;               // the ground-truth volume: 3-voxel Gaussians
  WindowOptions windows;                   // windowed Q: 64^3 at 32-voxel steps
  particles::ExtractionOptions extraction; // blobs for ghost counts and positions
  Vec3d ghost_mask_diameter_voxel{3.0, 3.0, 4.5};  // "true" region around each particle
  Vec3d detection_radius_voxel{1.5, 1.5, 1.8};     // acceptance ellipsoid semi-axes
  // Seeded slab in world z (mm), for the RSNR. NaN (default): the z range of the true particles.
  double slab_z_min_mm = std::numeric_limits<double>::quiet_NaN();
  double slab_z_max_mm = std::numeric_limits<double>::quiet_NaN();
  double snr_noise_margin_voxel = 2.25;    // noise slices start this far outside the slab
  int profile_lateral_margin_voxel = 0;    // the thesis averaged 400 x 400 of 512 x 512: 56
  int threads = 0;                         // > 0: overrides the thread count of every stage

  // Throws tomorig::Error (bad_input) naming the field that is out of range.
  void validate() const;
};

struct QualityReport {
  // Keys of `tomorig bench recon --json` (issue 4).
  double q_global = 0.0;
  double q_windowed = 0.0;
  double ghost_true_count_ratio = 0.0;
  double true_ghost_intensity_ratio = 0.0;
  std::array<double, 3> position_rms_voxel{0.0, 0.0, 0.0};
  double detected_fraction = 0.0;
  // Details behind them.
  std::size_t windows_used = 0;
  std::size_t true_blobs = 0, ghost_blobs = 0;
  double true_blob_mean_intensity = 0.0, ghost_blob_mean_intensity = 0.0;
  double ghost_intensity_fraction = 0.0;   // share of the total intensity outside the mask (voxel level)
  std::size_t true_particles = 0;          // true particles inside the grid
  std::size_t detected_particles = 0;      // blobs extracted from the reconstruction
  std::size_t matched_particles = 0;       // true detections
  std::array<double, 3> position_mean_voxel{0.0, 0.0, 0.0};  // bias of detected - true
  DepthProfile depth_profile;
  SignalToNoise snr;                       // snr.ratio is the RSNR
  double seconds = 0.0;                    // time of evaluate(), truth preparation excluded

  std::string brief() const;  // one line
};

class QualityEvaluator {
 public:
  // Builds the truth volume and the true-particle mask for `grid`. Throws tomorig::Error
  // (bad_input) on a bad grid, options or a non-finite particle position.
  QualityEvaluator(const VoxelGrid& grid, std::span<const Vec3d> true_particles_mm, const QualityOptions& options = {});
  ~QualityEvaluator();
  QualityEvaluator(QualityEvaluator&&) noexcept;
  QualityEvaluator& operator=(QualityEvaluator&&) noexcept;

  // Throws tomorig::Error (bad_input) if the volume's grid is not the evaluator's or the
  // volume is malformed.
  QualityReport evaluate(const SparseVolume& reconstruction) const;
  QualityReport evaluate(const DenseVolume& reconstruction) const;

  const SparseVolume& truth_volume() const;
  const VoxelGrid& grid() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Shorthands for a single evaluation on the reconstruction's own grid.
QualityReport evaluate_quality(const SparseVolume& reconstruction, std::span<const Vec3d> true_particles_mm,
                               const QualityOptions& options = {});
QualityReport evaluate_quality(const DenseVolume& reconstruction, std::span<const Vec3d> true_particles_mm,
                               const QualityOptions& options = {});

}  // namespace tomorig::quality
