#pragma once
// Correction of traverse (stage) positioning errors, thesis Sect. 6.3.3: the target planes were
// not exactly where the traverse said. Per plane an offset (dx, dy, dz) is estimated by
// minimising the disparities (reprojection errors) of all cameras with their models held
// fixed, the world points are shifted by it, the models are re-fitted, and so on; then,
// optionally, a higher-order model is fitted to the corrected points. The models of this
// alternation are pinholes, as in the thesis; behind a window (final_model "refractive") they
// are refractive models, since a pinhole's disparities there carry the refraction's error
// (which grows with depth in the medium) into the plane offsets.
//
//   calibration::TraverseCorrectionOptions opt;            // final_model = "rational2"
//   auto result = calibration::correct_traverse(points_per_camera, image_sizes, opt);
//   result.offsets_mm[k];        // plane k (ascending nominal z), zero-mean gauge
//   result.models[c];            // the final model of camera c, fitted on corrected points
//
// Gauge (what the data cannot determine, fixed by convention; see remove_gauge):
//  - a shift common to all planes is a move of all cameras: offsets have zero mean;
//  - offsets growing linearly with z in x and in z (a shear of the traverse in x, a scale of
//    its z steps) are an affine map of the x-z plane, which cameras yawed about the y axis
//    (as in the thesis and in calib-thesis) absorb exactly into their fx, cx and pose: the
//    x and z offsets have no linear trend over z. (A linear trend in y is observable by
//    pinholes and kept; refractive models, whose window tilt and tangential lens terms are
//    fitted per camera, absorb it too, so with them the y offsets have no linear trend either.)
// Compare an estimate with a truth only after putting the truth into this gauge.
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct TraverseCorrectionOptions {
  int max_cycles = 30;          // alternations of (offset estimate, model re-fit)
  double tolerance_um = 1e-3;   // stop once no offset changes by more than this in a cycle
  // Model fitted on the corrected points at the end: any fit_camera_model() name; "pinhole"
  // keeps the re-fitted pinholes, "refractive" (needs fit.window) the refractive models of the
  // alternation.
  std::string final_model = "rational2";
  FitOptions fit;  // for every fit; `camera` is replaced by the camera names below
  std::vector<std::string> camera_names;  // optional, one per camera ("camera 1", ... if empty)

  // Empty if valid, else a message naming the field.
  std::string validate() const;
};

struct TraverseCorrectionResult {
  std::vector<double> plane_z_mm;  // nominal z of each plane, ascending
  // Joint estimate over all cameras, per plane (mm), in the gauge above. Add it to a
  // plane's nominal world points to get where the target really was.
  std::vector<Vec3d> offsets_mm;
  // [camera][plane]: the same estimate from one camera alone with its final alternation model
  // fixed
  // (the thesis's Table 6.3 reports these; out-of-plane components are poorly determined by a
  // single view, which is why the correction itself uses the joint estimate).
  std::vector<std::vector<Vec3d>> per_camera_offsets_mm;
  int cycles = 0;
  bool converged = false;
  std::string alternation_model;  // alternation_model_for(final_model)
  std::vector<std::unique_ptr<CameraModel>> alternation_models;  // re-fitted on corrected points
  std::vector<FitReport> alternation_reports;
  std::vector<std::unique_ptr<CameraModel>> models;    // final_model on corrected points
  std::vector<FitReport> reports;
  std::vector<std::vector<PointCorrespondence>> corrected_points;  // per camera
};

// points_per_camera[c]: camera c's correspondences, world z = the plane's nominal z (points of
// one plane share z within 1e-6 mm). Needs >= 2 cameras and >= 2 planes seen by them.
// Throws tomorig::Error (bad_input) for bad options or data, naming camera and plane.
TraverseCorrectionResult correct_traverse(std::span<const std::vector<PointCorrespondence>> points_per_camera,
                                          std::span<const ImageSize> image_sizes,
                                          const TraverseCorrectionOptions& options);

// The model whose disparities the alternation minimises: "refractive" for that final model,
// else "pinhole".
std::string alternation_model_for(const std::string& final_model);

// Puts per-plane offsets into the gauge above, in place: subtracts their mean and the
// least-squares linear trend over z of their x and z components (and of y if remove_y_trend,
// the gauge of the refractive alternation).
void remove_gauge(std::span<Vec3d> offsets_mm, std::span<const double> plane_z_mm, bool remove_y_trend = false);

// The points with each plane's offset added to its world points (planes matched by nominal z).
std::vector<PointCorrespondence> apply_plane_offsets(std::span<const PointCorrespondence> points,
                                                     std::span<const double> plane_z_mm,
                                                     std::span<const Vec3d> offsets_mm);

}  // namespace tomorig::calibration
