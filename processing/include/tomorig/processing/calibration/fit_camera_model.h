#pragma once
// Fitting a camera model to point correspondences (thesis Appendix A), one entry point for
// every model, so that `tomorig calibrate` can take the model name from the command line:
//
//   calibration::FitOptions options;  options.camera = "camera 1";
//   calibration::FitReport report;
//   auto model = calibration::fit_camera_model("rational2", points, {1600, 1200}, options, report);
//
// Models: "dlt" (SVD of the normalised system Eq. A.2, LM on Eq. A.3), "pinhole" (K, R, t
// from the DLT, LM on Eq. A.3), "pinhole_distortion" (the pinhole with radial and tangential
// lens distortion, lens_camera.h), "refractive" (that behind a flat window, needs
// FitOptions::window), "rational2" (Eq. A.4, started from the DLT), "soloff3"
// (Eq. A.5), "twoplane" (per-plane 2-D mappings). See docs/calibration.md.
//
// Errors (tomorig::Error, each message names options.camera and, where it applies, the plane):
//   bad_input: unknown model, bad options, too few points, a non-finite value, points on one
//              plane (or too few planes) for a model that needs depth, degenerate geometry;
//   runtime:   the LM did not converge (unless options.require_convergence is false).
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

// The models fit_camera_model() fits from the points alone, in the order of increasing
// complexity: pinhole, dlt, pinhole_distortion, twoplane, rational2, soloff3.
const std::vector<std::string>& camera_model_names();
// Those and "refractive" (a pinhole with distortion behind a flat window, refractive_camera.h),
// which also needs FitOptions::window.
const std::vector<std::string>& all_camera_model_names();

std::unique_ptr<CameraModel> fit_camera_model(std::string_view model_name,
                                              std::span<const PointCorrespondence> points,
                                              ImageSize image_size, const FitOptions& options,
                                              FitReport& report);

// Residuals of `model` over `points` (forward px, reverse um via back_project at the known z),
// filling the residual fields of `report` and its point and plane counts.
void measure_residuals(const CameraModel& model, std::span<const PointCorrespondence> points, FitReport& report);

}  // namespace tomorig::calibration
