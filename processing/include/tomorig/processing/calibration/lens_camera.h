#pragma once
// Pinhole camera with lens distortion (Brown-Conrady): radial k1, k2, k3 and tangential p1,
// p2, applied to the ideal image coordinates x = x_c / z_c, y = y_c / z_c of the pinhole
// frame (pinhole_camera.h):
//
//   r² = x² + y²,  radial = 1 + k1 r² + k2 r⁴ + k3 r⁶
//   x_d = x radial + 2 p1 x y + p2 (r² + 2 x²)
//   y_d = y radial + p1 (r² + 2 y²) + 2 p2 x y
//   u = fx x_d + cx,  v = fy y_d + cy
//
// (the form OpenCV and most calibration tools use, so coefficients can be compared). Model
// name "pinhole_distortion". back_project and line_of_sight undo the distortion by Newton's
// method on the 2 x 2 system, exact to ~1e-12 of the ideal coordinates.
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace tomorig::calibration {

struct LensDistortion {
  double k1 = 0, k2 = 0, k3 = 0;  // radial
  double p1 = 0, p2 = 0;          // tangential (decentring)

  // Ideal (undistorted) normalised image coordinates -> distorted ones.
  Vec2d distort(const Vec2d& ideal) const;
  // The inverse, by Newton's method started at `distorted`. Throws tomorig::Error (runtime)
  // if it does not converge (a point beyond the fold of a strongly distorting lens).
  Vec2d undistort(const Vec2d& distorted) const;
};

class LensCamera final : public CameraModel {
 public:
  // Throws tomorig::Error (bad_input) as PinholeCamera does, or for a non-finite coefficient.
  LensCamera(const PinholeParameters& pinhole, const LensDistortion& distortion);

  const PinholeCamera& pinhole() const { return pinhole_; }
  const LensDistortion& distortion() const { return distortion_; }

  std::string model_name() const override { return "pinhole_distortion"; }
  Vec2d project(const Vec3d& world) const override;
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  // The pixel with the distortion removed: where the ideal pinhole would see the same ray.
  Vec2d ideal_pixel(const Vec2d& pixel) const;

  PinholeCamera pinhole_;
  LensDistortion distortion_;
};

}  // namespace tomorig::calibration
