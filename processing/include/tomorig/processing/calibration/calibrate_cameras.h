#pragma once
// Calibrating a set of cameras from their point correspondences, as `tomorig calibrate` does:
// every listed model is fitted to every camera and reported on its own (a model the points
// cannot determine, or a fit that fails, is reported beside the others instead of ending the
// run); optionally the target planes' traverse errors are corrected first (thesis Sect. 6.3.3),
// each model is cross-validated by leaving one plane out, and the model to store is chosen by
// that error. The residuals per plane are those of thesis Tables 5.3 and 6.4.
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/core/geometry.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct PlaneResidual {
  double z_mm = 0;
  int points = 0;
  double forward_px = 0;  // mean
  double reverse_um = 0;  // mean
};

struct ModelResult {
  int camera = 0;
  FitReport report;
  std::vector<PlaneResidual> planes;  // by increasing z
  std::string error;                  // why the model was refused or failed ("" if fitted)
};

// Residuals of `model` on each plane (points grouped by equal z) of `points`.
std::vector<PlaneResidual> plane_residuals(const CameraModel& model, std::span<const PointCorrespondence> points);

// Traverse (stage) offsets found by the traverse correction (thesis Table 6.3), in the gauge of
// traverse_correction.h.
struct StageOffsets {
  std::vector<double> plane_z_mm;                         // nominal, ascending
  std::vector<Vec3d> offsets_mm;                          // joint estimate per plane
  std::vector<std::vector<Vec3d>> per_camera_offsets_mm;  // [camera][plane]
  std::vector<std::string> camera_names;
  int cycles = 0;
  bool converged = false;
};

// Cross-validation of one model on one camera: each plane (or each point) in turn is left out,
// the model fitted to the others and its error measured on what was left out. Leaving planes
// out tests the model between and beyond the planes (depth); leaving points out tests it within
// the calibrated planes, where a plane left out would leave too few planes (2 or 3 planes).
enum class LeaveOut { plane, point };

struct CrossValidation {
  int camera = 0;
  std::string model;
  LeaveOut left_out = LeaveOut::plane;
  int folds = 0;      // planes (or points) left out in turn
  int points = 0;     // points evaluated (all of them, each once)
  double rms_px = 0;  // forward residual on what was left out
  double max_px = 0;
  std::string error;  // why a fold could not be fitted ("" if all could)
};
CrossValidation cross_validate(const std::string& model, std::span<const PointCorrespondence> points, ImageSize size,
                               const FitOptions& options, int camera, LeaveOut left_out = LeaveOut::plane);

// The automatic choice: the model whose cross-validated RMS, averaged over the cameras, is
// lowest among those that every camera could fit; the reason names the runner-up. Throws
// bad_input if none.
struct AutoChoice {
  std::string model;
  std::string reason;
};
AutoChoice choose_model(const std::vector<CrossValidation>& results, const std::vector<std::string>& models);

struct CalibrateCamerasOptions {
  std::vector<std::string> models;  // fitted in this order (fit_camera_model() names)
  std::string stored;               // the model whose fits form the calibration; ignored when choosing
  bool choose_model = false;        // cross-validate and store the model with the lowest error
  bool cross_validate = false;      // report the cross-validated error of every model
  LeaveOut leave_out = LeaveOut::plane;  // what cross-validation (and the automatic choice) leaves out
  bool stage_correction = false;    // correct the traverse first; the last model comes from the correction
  std::vector<std::string> camera_names;  // one per camera, for the traverse correction's messages
  // For every fit (max_iterations, window, ...); `camera` is set per camera ("camera 0", ...).
  FitOptions fit;
  // Each model that is refused or fails, and the automatic choice, as they happen ("warning:
  // pinhole: refused: ..."; "error ..." for the stored model).
  std::function<void(const std::string&)> notice;
};

struct CalibrateCamerasReport {
  std::vector<ModelResult> results;         // per camera, per model, in order
  std::vector<CrossValidation> validation;  // empty unless cross-validated
  std::optional<StageOffsets> offsets;      // with the traverse correction
  std::string stored;                       // the model stored (chosen, or as asked)
  std::vector<CameraCalibration> calibrations;  // the stored model of each camera that fitted
  // Set if the stored model failed for some camera (then nothing should be written).
  std::optional<ErrorKind> stored_failure;

  // "no calibration written: the stored model X failed for camera 1, 2 (...)"; "" if none failed.
  std::string failure_message() const;
  // A stored model that misses its own points by more than kCalibrationWarnRmsPx will misplace
  // particles: one rms_warning() per such camera.
  std::vector<std::string> poor_fit_warnings() const;
};

// points[c], sizes[c]: camera c's correspondences and image size. Throws bad_input for options
// that cannot work (an unknown model, a stored model not fitted, a traverse correction without
// enough cameras or planes, no model that every camera can cross-validate).
CalibrateCamerasReport calibrate_cameras(std::span<const std::vector<PointCorrespondence>> points,
                                         std::span<const ImageSize> sizes, const CalibrateCamerasOptions& options);

}  // namespace tomorig::calibration
