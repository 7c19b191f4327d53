// detect_target: dispatch on the kind of target.
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {

TargetDetection detect_target(const Image& image, const TargetSpec& spec, double z_mm, const std::string& what) {
  if (const auto* dots = std::get_if<DotGridSpec>(&spec)) return detect_dot_grid(image, *dots, z_mm, what);
  return detect_chessboard(image, std::get<ChessboardSpec>(spec), z_mm, what);
}

}  // namespace tomorig::calibration
