#pragma once
// Volume self-calibration (thesis Sect. 2.2 and 5.3, Wieneke 2008): corrects camera models
// with the particle images of the experiment itself.
//
//   1. detect the 2-D particle peaks of every camera image (sub-pixel, 3-point Gaussian);
//   2. triangulate candidate 3-D particles seen by all cameras (epipolar search within a
//      search radius, least-squares point from all lines of sight);
//   3. bin each camera's disparities (projected 3-D point minus detected peak) over
//      sub-volumes and take the most probable disparity of each (disparity-map peak, refined
//      by the mean of the disparities near it), so ghost matches, which scatter, drop out;
//   4. correct each camera: smooth the sub-volume disparities with a low-order polynomial
//      field and refit the camera's own model type to a lattice of (world point, pixel minus
//      disparity) correspondences;
//   5. repeat with a shrinking search radius until every camera's mean disparity is below
//      the tolerance.
// docs/calibration.md ("Volume self-calibration") explains the decisions, e.g. the gauge.
//
//   calibration::SelfCalibrationOptions options;
//   auto result = calibration::self_calibrate(models, sizes, snapshots, bounds, options);
//   // result.models: corrected; result.before() / result.after(): Table 5.4 figures
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

// The measurement volume (world mm): particles are triangulated inside it and it is split
// into the sub-volumes.
struct VolumeBounds {
  Vec3d min;
  Vec3d max;
  // Empty if valid (finite, max > min on every axis), else a message.
  std::string validate() const;
};

struct SelfCalibrationOptions {
  // Sub-volumes along x, y, z (Wieneke uses e.g. 5 x 5 x 3).
  int subvolumes_x = 5, subvolumes_y = 5, subvolumes_z = 3;
  // Search radius of the first pass, px: must exceed the largest misalignment in the images.
  // Later passes halve it down to min_search_radius_px, which keeps ghost matches rare.
  double search_radius_px = 2.0;
  double min_search_radius_px = 0.75;
  // Converged when every camera's mean sub-volume disparity is below this (px).
  double tolerance_px = 0.05;
  // Corrections applied at most; one more pass then measures the result.
  int max_iterations = 6;
  // Peaks below this intensity (counts) are ignored; 0: 10 % of the image's 99.9th percentile.
  double peak_threshold = 0;
  // Radius (px) around the disparity-map peak whose disparities are averaged into the
  // sub-volume's disparity.
  double peak_window_px = 0.4;
  // A sub-volume needs this many matches near its disparity peak to count, per camera.
  int min_matches_per_subvolume = 10;
  // Gauge of the correction. true: per sub-volume, choose the common world shift that makes
  // the corrections sparsest (least sum of magnitudes over the cameras), so one misaligned
  // camera takes its whole error instead of dragging the world frame (and the other cameras)
  // along. false: apply the least-squares disparities as they are (Wieneke's plain form).
  bool sparse_gauge = true;
  // Throw tomorig::Error (runtime) naming the camera if not converged within max_iterations.
  bool require_convergence = true;
  // Names of the cameras in messages and reports; empty: "camera 0", "camera 1", ...
  std::vector<std::string> camera_names;

  // Empty if valid, else a message naming the field, its value and the rule.
  std::string validate() const;
};

// The images of all cameras at one instant (one exposure of one set), in camera order.
struct ParticleSnapshot {
  std::vector<Image> images;
};

// Sub-volume disparity magnitudes of one camera over a group of sub-volumes.
struct DisparityFigures {
  double mean_px = 0;  // mean |disparity| over the group's valid sub-volumes
  double max_px = 0;
  // The same disparity in the world (image-to-world mapping, "rev." of Table 5.4): distance
  // between the back-projections of the sub-volume centre's pixel with and without it.
  double mean_um = 0;
  int subvolumes = 0;  // valid sub-volumes in the group
};

struct CameraDisparity {
  DisparityFigures volume;       // all sub-volumes
  DisparityFigures z_min_layer;  // the sub-volumes next to the z-min bounding plane
  DisparityFigures z_max_layer;  // the sub-volumes next to the z-max bounding plane
};

// One triangulation + disparity measurement with the models of that moment.
struct SelfCalibrationPass {
  double search_radius_px = 0;
  std::size_t matches = 0;         // candidate 3-D particles (ghosts included)
  std::size_t unique_matches = 0;  // reference peaks with exactly one candidate
  std::vector<CameraDisparity> cameras;
  double largest_mean_px() const;  // max over cameras of cameras[i].volume.mean_px
};

struct SelfCalibrationResult {
  std::vector<std::shared_ptr<const CameraModel>> models;  // corrected (or the input, if unchanged)
  std::vector<std::optional<FitReport>> refits;  // per camera: the last refit, if any
  std::vector<std::size_t> peaks;                // detected peaks per camera, all snapshots
  std::vector<SelfCalibrationPass> passes;       // front(): before, back(): after
  double z_min_layer_mm = 0, z_max_layer_mm = 0;  // z of the bounding layers' centres
  int corrections = 0;
  bool converged = false;

  const SelfCalibrationPass& before() const { return passes.front(); }
  const SelfCalibrationPass& after() const { return passes.back(); }
};

// Throws tomorig::Error: bad_input for bad options or bounds, mismatched camera counts or
// image sizes, no snapshots, or too few particles to measure a camera's disparities (naming
// the camera and what to change); runtime if the disparities do not fall below the tolerance
// within max_iterations (naming the cameras, unless require_convergence is false) or a refit
// fails.
SelfCalibrationResult self_calibrate(std::span<const std::shared_ptr<const CameraModel>> models,
                                     std::span<const ImageSize> image_sizes,
                                     std::span<const ParticleSnapshot> snapshots, const VolumeBounds& bounds,
                                     const SelfCalibrationOptions& options);

// ---- Tools for testing self-calibration -------------------------------------------------

// `model` misaligned in its image: every projection rotated by rotation_deg about the image
// centre ((W - 1) / 2, (H - 1) / 2), then shifted by shift_px, as a camera that moved after
// calibration. Refits the model's own type to a lattice over `bounds` (exact for pinhole and
// dlt). Throws tomorig::Error as fit_camera_model does.
std::unique_ptr<CameraModel> misaligned_camera(const CameraModel& model, ImageSize image_size,
                                               const VolumeBounds& bounds, Vec2d shift_px, double rotation_deg,
                                               FitReport& report);

struct ProjectionDifference {
  double mean_px = 0;
  double max_px = 0;
  std::size_t points = 0;
};
// How far apart two models project the same world points (e.g. a corrected model against
// the true camera, over the true particle positions).
ProjectionDifference projection_difference(const CameraModel& a, const CameraModel& b,
                                           std::span<const Vec3d> points);

}  // namespace tomorig::calibration
