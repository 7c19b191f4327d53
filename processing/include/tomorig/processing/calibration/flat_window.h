#pragma once
// A flat window between the cameras (in air) and the medium the flow is in: its pose, its
// thickness and the three refractive indices. Used by the refractive camera model
// (refractive_camera.h) and by its fit (FitOptions::window).
#include <string>

#include "tomorig/core/geometry.h"

namespace tomorig::calibration {

struct FlatWindow {
  // Unit normal of the faces in world coordinates, pointing from the camera into the medium.
  Vec3d normal{0, 0, 1};
  // The face between window and medium: the points X with normal . X = medium_face_mm.
  double medium_face_mm = 0;
  double thickness_mm = 0;  // the air face is at normal . X = medium_face_mm - thickness_mm
  double n_air = 1.0, n_window = 1.49, n_medium = 1.33;

  // Empty if valid, else what is wrong (indices >= 1 and finite, thickness >= 0, |normal| = 1).
  std::string validate() const;
};

}  // namespace tomorig::calibration
