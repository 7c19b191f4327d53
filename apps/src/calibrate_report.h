#pragma once
// The residual report of `tomorig calibrate` (thesis Tables 5.3 and 6.4) as text and JSON: per
// camera and model the mean forward residual (px) and reverse residual (um), and the same per
// calibration plane. The figures come from calibration::calibrate_cameras().
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "tomorig/processing/calibration/calibrate_cameras.h"

namespace tomorig::app {

using calibration::CrossValidation;
using calibration::LeaveOut;
using calibration::ModelResult;
using calibration::PlaneResidual;
using calibration::StageOffsets;

// Per plane: the joint offset, then each camera's own estimate, in um.
void print_stage_offsets(const StageOffsets& s);
nlohmann::json stage_offsets_json(const StageOffsets& s);

void print_cross_validation(const std::vector<CrossValidation>& results);
nlohmann::json cross_validation_json(const std::vector<CrossValidation>& results);

// Plain-text tables: one row per camera and model (RMS, mean and max of the forward residual in
// px and of the reverse residual in um at the target; a refused model's reason), then one per
// camera, model and plane. `out` empty: nothing was written.
void print_report(const std::vector<ModelResult>& results, const std::string& stored, const std::string& out);
nlohmann::json report_json(const std::vector<ModelResult>& results);

}  // namespace tomorig::app
