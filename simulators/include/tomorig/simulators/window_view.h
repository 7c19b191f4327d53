#pragma once
// Ground truth for a camera behind a flat window into a medium (issue 18): the true pinhole
// camera in air, the true window, and where the camera truly sees a point in the medium.
// Written independently of calibration::RefractiveCamera (which solves the in-plane angle):
// here the pixel's ray is traced through both faces and the pixel is corrected by Newton's
// method until the ray passes through the point, so tests compare two different solutions.
//
//   sim::WindowView view{camera, window};
//   Vec2d pixel = view.project({1, 2, 30});          // throws runtime if not reachable
//   Vec3d p = view.back_project(pixel, 30);          // on the plane z = 30 mm
#include "tomorig/core/geometry.h"
#include "tomorig/processing/calibration/flat_window.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace tomorig::sim {

struct WindowView {
  calibration::PinholeCamera camera;
  calibration::FlatWindow window;

  // The ray in the medium seen at `pixel` (origin on the medium face, unit direction).
  Ray medium_ray(const Vec2d& pixel) const;
  Vec3d back_project(const Vec2d& pixel, double world_z) const;
  Vec2d project(const Vec3d& world) const;
};

}  // namespace tomorig::sim
