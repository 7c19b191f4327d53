#pragma once
// The calibration file (TOML): per camera its id, image size, model type, coefficients,
// normalisation and fit report. Written with full double precision, so a saved model
// projects exactly as it did before saving. Format: docs/calibration.md.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct CameraCalibration {
  int id = 0;
  ImageSize image_size;
  std::shared_ptr<const CameraModel> model;
  FitReport report;
};

// A stored model that misses its own fitted points by more than this RMS will misplace
// particles; `calibrate` warns when it stores one, `reconstruct` and `process` when they load one.
inline constexpr double kCalibrationWarnRmsPx = 0.5;

// The warning for `c` ("camera 0: the stored pinhole model leaves 5.5 px RMS ..."), or "" if
// its RMS (from its fit report) is within kCalibrationWarnRmsPx.
std::string rms_warning(const CameraCalibration& c);

// Throws tomorig::Error: bad_input if a model is of a kind the file cannot hold, runtime if
// the file cannot be written.
void save_calibration(const std::filesystem::path& path, const std::vector<CameraCalibration>& cameras);

// Validates everything: a missing, mistyped or non-finite value throws tomorig::Error
// (bad_input) naming the camera and the key (e.g. "camera 2: coefficients.forward[7] is nan").
std::vector<CameraCalibration> load_calibration(const std::filesystem::path& path);

}  // namespace tomorig::calibration
