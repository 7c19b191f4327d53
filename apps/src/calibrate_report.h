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

// Plain-text tables: one row per camera and model, then one per camera, model and plane.
void print_report(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out);
nlohmann::json report_json(const std::vector<ModelResult>& results);

}  // namespace tomorig::app
