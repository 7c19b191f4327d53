#pragma once
// What a camera-model fit takes and what it gives back: point correspondences, the
// normalisation of thesis Appendix A.1, the fit options and the fit report.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/processing/calibration/flat_window.h"

namespace tomorig::calibration {

// One calibration point: a world position (mm) and where the camera saw it (pixels, in the
// pixel convention of camera_model.h).
struct PointCorrespondence {
  Vec3d world;
  Vec2d pixel;
};

struct ImageSize {
  int width = 0, height = 0;
};

// Thesis Eq. A.1, Hartley's variant: translate each point cloud's centroid to the origin and
// scale it so that the mean distance from the origin is sqrt(3) (world) and sqrt(2) (image),
// i.e. the "average" point becomes (1, 1, 1) and (1, 1). Fits run in these coordinates.
struct Normalization {
  Vec3d world_centre;
  double world_scale = 1;  // mm per normalised unit: x~ = (x - centre) / world_scale
  Vec2d image_centre;
  double image_scale = 1;  // pixels per normalised unit

  Vec3d to_normalised(const Vec3d& world) const {
    return (world - world_centre) * (1.0 / world_scale);
  }
  Vec3d to_world(const Vec3d& normalised) const { return normalised * world_scale + world_centre; }
  Vec2d to_normalised(const Vec2d& pixel) const {
    return {(pixel.x - image_centre.x) / image_scale, (pixel.y - image_centre.y) / image_scale};
  }
  Vec2d to_pixel(const Vec2d& normalised) const {
    return {normalised.x * image_scale + image_centre.x, normalised.y * image_scale + image_centre.y};
  }
};

// Throws tomorig::Error (bad_input) if the points are empty or all coincide (in world or image).
Normalization compute_normalization(std::span<const PointCorrespondence> points);

struct FitOptions {
  // Names the camera in error messages and reports ("camera 2"). Set it to the camera id.
  std::string camera = "camera";
  // Levenberg-Marquardt iterations before giving up. Most fits converge in 1-15; rational2
  // on data without lens distortion can take ~100, since its numerator and denominator then
  // share a free common factor and the LM walks a flat valley. More rarely helps bad data.
  int max_iterations = 500;
  // LM stops when the relative decrease of the squared reprojection error, or the relative
  // size of a step, falls below this.
  double tolerance = 1e-10;
  // If the LM does not converge within max_iterations, fit_camera_model tries again with
  // retry_factor times as many iterations (and, for rational2, from a second start) before it
  // gives up: then throw (true) or return the last iterate with report.converged = false.
  bool require_convergence = true;
  int retry_factor = 4;  // 1: no second attempt
  // Newton steps on the forward model that polish each back-projection of the polynomial and
  // two-plane models, so that back_project/line_of_sight agree with project (0: use the
  // fitted inverse mapping as it is).
  int newton_steps = 4;
  // The "refractive" model: the window the cameras look through (required for it). Its
  // thickness and indices are fixed; its pose (normal and medium face) is the start of the
  // fit if fit_window_pose, else fixed too. fit_medium_index also fits n_medium.
  std::optional<FlatWindow> window;
  bool fit_window_pose = true;
  bool fit_medium_index = false;

  // Empty if valid, else a message naming the field, its value and the rule.
  std::string validate() const;
};

struct FitReport {
  std::string model;   // "pinhole", "dlt", "soloff3", "rational2", "twoplane"
  std::string camera;  // FitOptions::camera
  int points = 0;
  int planes = 0;      // distinct z values among the points
  double forward_mean_px = 0;  // mean of Eq. A.3 over all points
  double forward_rms_px = 0;   // root mean square of the same distances (what other tools report)
  double forward_max_px = 0;
  // Mean/max distance (micrometres) between each world point and back_project(its pixel, its z).
  double reverse_mean_um = 0;
  double reverse_rms_um = 0;
  double reverse_max_um = 0;
  // The same for the fitted inverse mapping alone (soloff3, rational2), before Newton polish.
  std::optional<double> inverse_mapping_mean_um;
  int iterations = 0;  // LM iterations of the forward fit (inverse fit not counted)
  // How the fit got there if the first attempt did not converge ("" if it did), e.g.
  // "converged on a second attempt with 2000 iterations".
  std::string retry;
  bool converged = false;
  Normalization normalization;

  std::string brief() const;  // one line: model, camera, residuals, iterations
};

}  // namespace tomorig::calibration
