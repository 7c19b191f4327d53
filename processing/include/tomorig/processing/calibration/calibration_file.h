#pragma once
// The calibration file (TOML): per camera its id, image size, model type, coefficients,
// normalisation and fit report. Written with full double precision, so a saved model
// projects exactly as it did before saving. Format: docs/calibration.md.
#include <filesystem>
#include <memory>
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

// Throws tomorig::Error: bad_input if a model is of a kind the file cannot hold, runtime if
// the file cannot be written.
void save_calibration(const std::filesystem::path& path, const std::vector<CameraCalibration>& cameras);

// Validates everything: a missing, mistyped or non-finite value throws tomorig::Error
// (bad_input) naming the camera and the key (e.g. "camera 2: coefficients.forward[7] is nan").
std::vector<CameraCalibration> load_calibration(const std::filesystem::path& path);

}  // namespace tomorig::calibration
