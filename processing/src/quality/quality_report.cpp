#include "tomorig/processing/quality/quality_report.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/particles/sparsify.h"
#include "tomorig/processing/quality/ellipsoid_mask.h"
#include "tomorig/processing/quality/ghost_analysis.h"
#include "tomorig/processing/quality/position_matching.h"

namespace tomorig::quality {

void QualityOptions::validate() const {
  truth.validate();
  windows.validate();
  extraction.validate();
  const Vec3d& d = ghost_mask_diameter_voxel;
  if (!(d.x > 0 && d.y > 0 && d.z > 0) || !std::isfinite(d.x) || !std::isfinite(d.y) || !std::isfinite(d.z))
    throw bad_input(fmt::format("quality: ghost_mask_diameter_voxel = {} x {} x {}; each must be a finite value > 0",
                                d.x, d.y, d.z));
  MatchOptions{detection_radius_voxel}.validate();
  if (std::isnan(slab_z_min_mm) != std::isnan(slab_z_max_mm))
    throw bad_input("quality: give both slab_z_min_mm and slab_z_max_mm, or neither (then the true particles' z range is used)");
  if (!std::isnan(slab_z_min_mm) && !(slab_z_min_mm <= slab_z_max_mm && std::isfinite(slab_z_min_mm) && std::isfinite(slab_z_max_mm)))
    throw bad_input(fmt::format("quality: slab z range [{}, {}] mm; it needs finite bounds with min <= max",
                                slab_z_min_mm, slab_z_max_mm));
  if (!(snr_noise_margin_voxel >= 0.0))
    throw bad_input(fmt::format("quality: snr_noise_margin_voxel = {}; it must be >= 0", snr_noise_margin_voxel));
  if (profile_lateral_margin_voxel < 0)
    throw bad_input(fmt::format("quality: profile_lateral_margin_voxel = {}; it must be >= 0", profile_lateral_margin_voxel));
  if (threads < 0) throw bad_input(fmt::format("quality: threads = {}; use 0 (default) or > 0", threads));
}

std::string QualityReport::brief() const {
  return fmt::format(
      "Q {:.4f} (windowed {:.4f}), ghost/true blobs {:.3g} ({}/{}), true/ghost intensity {:.3g}, position RMS "
      "{:.3f}/{:.3f}/{:.3f} voxel, detected {:.2f} % of {}, RSNR {:.3g}, {:.3f} s",
      q_global, q_windowed, ghost_true_count_ratio, ghost_blobs, true_blobs, true_ghost_intensity_ratio,
      position_rms_voxel[0], position_rms_voxel[1], position_rms_voxel[2], 100.0 * detected_fraction, true_particles,
      snr.ratio, seconds);
}

struct QualityEvaluator::Impl {
  QualityOptions options;
  VoxelGrid grid;
  std::vector<Vec3d> truth_voxel;
  SparseVolume truth;
  EllipsoidMask mask;
  double slab_min_voxel = 0.0, slab_max_voxel = -1.0;  // empty: no slab
};

QualityEvaluator::QualityEvaluator(const VoxelGrid& grid, std::span<const Vec3d> true_particles_mm,
                                   const QualityOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  if (options.threads > 0) {
    m.options.truth.threads = options.threads;
    m.options.extraction.threads = options.threads;
  }
  m.options.validate();
  particles::detail::check_grid(grid, "quality");
  m.grid = grid;
  m.truth = gaussian_blob_volume(grid, true_particles_mm, m.options.truth);  // also rejects non-finite positions
  m.truth_voxel.reserve(true_particles_mm.size());
  for (const Vec3d& p : true_particles_mm) m.truth_voxel.push_back(grid.voxel_of(p));
  m.mask = EllipsoidMask(grid, m.truth_voxel, m.options.ghost_mask_diameter_voxel);
  if (!std::isnan(m.options.slab_z_min_mm)) {
    m.slab_min_voxel = (m.options.slab_z_min_mm - grid.origin.z) / grid.voxel_size;
    m.slab_max_voxel = (m.options.slab_z_max_mm - grid.origin.z) / grid.voxel_size;
  } else if (!m.truth_voxel.empty()) {
    const auto [lo, hi] = std::minmax_element(m.truth_voxel.begin(), m.truth_voxel.end(),
                                              [](const Vec3d& a, const Vec3d& b) { return a.z < b.z; });
    m.slab_min_voxel = lo->z;
    m.slab_max_voxel = hi->z;
  }
}

QualityEvaluator::~QualityEvaluator() = default;
QualityEvaluator::QualityEvaluator(QualityEvaluator&&) noexcept = default;
QualityEvaluator& QualityEvaluator::operator=(QualityEvaluator&&) noexcept = default;

const SparseVolume& QualityEvaluator::truth_volume() const { return impl_->truth; }
const VoxelGrid& QualityEvaluator::grid() const { return impl_->grid; }

QualityReport QualityEvaluator::evaluate(const SparseVolume& reconstruction) const {
  const auto start = std::chrono::steady_clock::now();
  const Impl& m = *impl_;
  particles::detail::check_same_grid(reconstruction.grid, m.grid, "the reconstruction", "the quality evaluator");
  QualityReport r;

  // Q checks the volume's structure before anything else reads it.
  const QualityFactor q = quality_factor(reconstruction, m.truth, m.options.windows, m.options.threads);
  r.q_global = q.global;
  r.q_windowed = q.windowed;
  r.windows_used = q.windows_used;

  const particles::ExtractionReport blobs = particles::extract_particles(reconstruction, m.options.extraction);
  const GhostAnalysis ghosts = classify_blobs(blobs.particles, m.mask);
  r.true_blobs = ghosts.true_blobs;
  r.ghost_blobs = ghosts.ghost_blobs;
  r.true_blob_mean_intensity = ghosts.true_mean_intensity;
  r.ghost_blob_mean_intensity = ghosts.ghost_mean_intensity;
  r.ghost_true_count_ratio = ghosts.ghost_true_count_ratio;
  r.true_ghost_intensity_ratio = ghosts.true_ghost_intensity_ratio;

  std::vector<Vec3d> detected;
  detected.reserve(blobs.particles.size());
  for (const particles::Particle& p : blobs.particles) detected.push_back(p.voxel);
  const PositionMatch match = match_positions(detected, m.truth_voxel, m.grid, MatchOptions{m.options.detection_radius_voxel});
  r.true_particles = match.true_particles;
  r.detected_particles = match.detections;
  r.matched_particles = match.matched;
  r.detected_fraction = match.detected_fraction;
  r.position_rms_voxel = {match.rms_voxel.x, match.rms_voxel.y, match.rms_voxel.z};
  r.position_mean_voxel = {match.mean_voxel.x, match.mean_voxel.y, match.mean_voxel.z};

  r.depth_profile = depth_profile(reconstruction, m.mask, &m.truth, m.options.profile_lateral_margin_voxel);
  double total = 0.0, ghost = 0.0;
  for (std::size_t k = 0; k < r.depth_profile.total.size(); ++k) {
    total += r.depth_profile.total[k];
    ghost += r.depth_profile.ghost_part[k];
  }
  r.ghost_intensity_fraction = total > 0.0 ? ghost / total : 0.0;
  if (m.slab_max_voxel >= m.slab_min_voxel)
    r.snr = reconstruction_snr(r.depth_profile.total, m.slab_min_voxel, m.slab_max_voxel, m.options.snr_noise_margin_voxel);
  else
    r.snr.ratio = std::numeric_limits<double>::quiet_NaN();
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

QualityReport QualityEvaluator::evaluate(const DenseVolume& reconstruction) const {
  const auto start = std::chrono::steady_clock::now();
  // Multiplicative reconstructions are non-negative; voxels <= 0 carry no signal.
  QualityReport r = evaluate(particles::sparsify(reconstruction, 0.0f, impl_->options.threads));
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

QualityReport evaluate_quality(const SparseVolume& reconstruction, std::span<const Vec3d> true_particles_mm,
                               const QualityOptions& options) {
  return QualityEvaluator(reconstruction.grid, true_particles_mm, options).evaluate(reconstruction);
}

QualityReport evaluate_quality(const DenseVolume& reconstruction, std::span<const Vec3d> true_particles_mm,
                               const QualityOptions& options) {
  return QualityEvaluator(reconstruction.grid, true_particles_mm, options).evaluate(reconstruction);
}

}  // namespace tomorig::quality
