#pragma once
// The residual report of `tomorig calibrate` (thesis Tables 5.3 and 6.4): per camera and model
// the mean forward residual (px) and reverse residual (um), and the same per calibration plane.
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "tomorig/core/geometry.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::app {

struct PlaneResidual {
  double z_mm = 0;
  int points = 0;
  double forward_px = 0;  // mean
  double reverse_um = 0;  // mean
};

struct ModelResult {
  int camera = 0;
  calibration::FitReport report;
  std::vector<PlaneResidual> planes;  // by increasing z
  std::string error;                  // why the model was refused or failed ("" if fitted)
};

// Residuals of `model` on each plane (points grouped by equal z) of `points`.
std::vector<PlaneResidual> plane_residuals(const calibration::CameraModel& model,
                                           std::span<const calibration::PointCorrespondence> points);

// Traverse (stage) offsets found by --stage-correction (thesis Table 6.3), in the gauge of
// traverse_correction.h.
struct StageOffsets {
  std::vector<double> plane_z_mm;                       // nominal, ascending
  std::vector<Vec3d> offsets_mm;                        // joint estimate per plane
  std::vector<std::vector<Vec3d>> per_camera_offsets_mm;  // [camera][plane]
  std::vector<std::string> camera_names;
  int cycles = 0;
  bool converged = false;
};

// Per plane: the joint offset, then each camera's own estimate, in um.
void print_stage_offsets(const StageOffsets& s);
nlohmann::json stage_offsets_json(const StageOffsets& s);

// Cross-validation of one model on one camera: each plane (or each point) in turn is left out,
// the model fitted to the others and its error measured on what was left out. Leaving planes
// out tests the model between and beyond the planes (depth); leaving points out tests it within
// the calibrated planes, where a plane left out would leave too few planes (2 or 3 planes).
enum class LeaveOut { plane, point };

struct CrossValidation {
  int camera = 0;
  std::string model;
  LeaveOut left_out = LeaveOut::plane;
  int folds = 0;           // planes (or points) left out in turn
  int points = 0;          // points evaluated (all of them, each once)
  double rms_px = 0;       // forward residual on the left-out planes
  double max_px = 0;
  std::string error;       // why a fold could not be fitted ("" if all could)
};
CrossValidation cross_validate(const std::string& model, std::span<const calibration::PointCorrespondence> points,
                               calibration::ImageSize size, const calibration::FitOptions& options, int camera,
                               LeaveOut left_out = LeaveOut::plane);

// --models auto: the model whose cross-validated RMS, averaged over the cameras, is lowest among
// those that every camera could fit; the reason names the runner-up. Throws bad_input if none.
struct AutoChoice {
  std::string model;
  std::string reason;
};
AutoChoice choose_model(const std::vector<CrossValidation>& results, const std::vector<std::string>& models);

void print_cross_validation(const std::vector<CrossValidation>& results);
nlohmann::json cross_validation_json(const std::vector<CrossValidation>& results);

// Plain-text tables: one row per camera and model (RMS, mean and max of the forward residual in
// px and of the reverse residual in um at the target; a refused model's reason), then one per
// camera, model and plane. `out` empty: nothing was written.
void print_report(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out);
nlohmann::json report_json(const std::vector<ModelResult>& results);

}  // namespace tomorig::app
