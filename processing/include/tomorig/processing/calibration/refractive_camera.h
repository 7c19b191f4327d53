#pragma once
// A camera in air looking through a flat window into a medium (water, a pressurised chamber):
// a pinhole with lens distortion (lens_camera.h) plus two parallel refracting faces,
//
//   air (n_air) | window (n_window, thickness t) | medium (n_medium)
//
// Model name "refractive". project() finds the ray from the projection centre to the world
// point that obeys Snell's law at both faces: it lies in the plane through the centre, the
// point and the window normal, so it is one unknown (the sine of the angle in air), solved by
// a safeguarded Newton iteration on the in-plane offset; then the lens camera images the ray.
// back_project() and line_of_sight() trace the pixel's ray through both faces (vector form of
// Snell's law); the line of sight returned is the ray in the medium.
#include "tomorig/processing/calibration/flat_window.h"
#include "tomorig/processing/calibration/lens_camera.h"

namespace tomorig::calibration {

class RefractiveCamera final : public CameraModel {
 public:
  // Throws tomorig::Error (bad_input) if the window is invalid or the camera's projection
  // centre is not on the air side of the window.
  RefractiveCamera(const LensCamera& lens, const FlatWindow& window);

  const LensCamera& lens() const { return lens_; }
  const FlatWindow& window() const { return window_; }

  std::string model_name() const override { return "refractive"; }
  Vec2d project(const Vec3d& world) const override;
  // Throws tomorig::Error (runtime) if the pixel's ray does not reach the medium (it points
  // away from the window, or is totally reflected).
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

  // The direction (unit) in air, from the projection centre, of the refracted ray to `world`.
  Vec3d air_direction(const Vec3d& world) const;

 private:
  LensCamera lens_;
  FlatWindow window_;
  Vec3d centre_;
};

}  // namespace tomorig::calibration
