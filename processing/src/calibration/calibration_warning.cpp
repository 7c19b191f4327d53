// rms_warning: the one wording of the "calibration too poor" warning, for calibrate,
// reconstruct and process.
#include <fmt/core.h>

#include "tomorig/processing/calibration/calibration_file.h"

namespace tomorig::calibration {

std::string rms_warning(const CameraCalibration& c) {
  if (!(c.report.forward_rms_px > kCalibrationWarnRmsPx)) return {};
  return fmt::format("camera {}: the stored {} model leaves {:.3g} px RMS (max {:.3g} px) on its own points, above {} px; "
                     "reconstruction with it will lose or misplace particles: check the points, or fit a model that "
                     "follows the optics (pinhole_distortion, refractive, rational2)",
                     c.id, c.report.model, c.report.forward_rms_px, c.report.forward_max_px, kCalibrationWarnRmsPx);
}

}  // namespace tomorig::calibration
