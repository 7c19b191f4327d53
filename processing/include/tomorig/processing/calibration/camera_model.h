#pragma once
// The camera-model contract shared by calibration, reconstruction and the simulator:
// world (mm) -> pixel, pixel + world z -> world, and the line of sight through a pixel.
// Pixel convention: the centre of pixel (u, v) is at (u, v); column u grows to the right,
// row v grows downwards; an image of width W spans [-0.5, W - 0.5].
#include <memory>
#include <string>

#include "tomorig/core/geometry.h"

namespace tomorig::calibration {

class CameraModel {
 public:
  virtual ~CameraModel() = default;
  virtual std::string model_name() const = 0;  // "pinhole", "dlt", "soloff3", ...
  virtual Vec2d project(const Vec3d& world) const = 0;
  // The world point on plane z = world_z that images to `pixel`.
  virtual Vec3d back_project(const Vec2d& pixel, double world_z) const = 0;
  virtual Ray line_of_sight(const Vec2d& pixel) const = 0;
  virtual std::unique_ptr<CameraModel> clone() const = 0;
};

}  // namespace tomorig::calibration
