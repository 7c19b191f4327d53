#pragma once
// Images of dot calibration plates seen through any camera model (pinhole, pinhole with lens
// distortion, a camera behind a window): square or staggered lattices, one or two depth levels,
// a hollow or filled square origin marker and an optional +x triangle, as target_detection.h
// describes them. The plate is drawn exactly (each pixel supersampled against the plate on
// the level its ray meets), so detections can be judged against the camera's true projection.
//
//   sim::DotPlate plate;  plate.spec.spacing_mm = 2;  plate.spec.lattice = staggered;
//   plate.spec.level_offset_mm = 1;  plate.triangle_site = 2;
//   Image img = sim::render_dot_plate(camera, plate, z, 400, 320);
#include <cstdint>
#include <functional>

#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::sim {

struct DotPlate {
  calibration::DotGridSpec spec;  // pitch, lattice, level offset, origin, polarity
  double dot_radius_mm = 0.25;
  int half_extent = 25;           // sites |i|, |j| <= half_extent (pitches) on each level
  bool filled_origin = true;      // a filled square in place of the origin dot, else a frame round it
  int triangle_site = 0;          // > 0: a filled triangle in place of the dot at (k, 0), pointing +x
  double frame_contrast = 1.0;    // the hollow frame's ink relative to the dots'
  int samples = 6;                // per pixel and axis
  double paper_counts = 200, ink_counts = 3000;  // swapped for black dots
  double noise_counts = 0;        // Gaussian, seeded
  std::uint64_t seed = 1;

  // Throws tomorig::Error (bad_input) naming the field.
  void validate() const;
  // Ink (0..1) at plate coordinates (x, y) mm from the origin site, on level 0 or 1.
  double ink(double x, double y, int level) const;
};

// A 16-bit image of the plate with its origin site at world spec.origin_mm + (0, 0, z_mm)
// (the second level at + level_offset_mm along z) seen by `camera`.
Image render_dot_plate(const calibration::CameraModel& camera, const DotPlate& plate, double z_mm, int width, int height);

// The same through any view given by its back-projection (the world point on plane z seen at a
// pixel), e.g. a sim::WindowView, the simulator's own camera behind a window.
using BackProjection = std::function<Vec3d(const Vec2d& pixel, double world_z)>;
Image render_dot_plate(const BackProjection& back_project, const DotPlate& plate, double z_mm, int width, int height);

}  // namespace tomorig::sim
