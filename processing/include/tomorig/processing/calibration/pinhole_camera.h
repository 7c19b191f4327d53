#pragma once
// Pinhole camera (thesis Eq. 3.11): w [u v 1]^T = K [R | t] [x y z 1]^T.
#include "tomorig/processing/calibration/camera_model.h"

namespace tomorig::calibration {

struct PinholeParameters {
  double fx = 0, fy = 0;  // focal length, pixels
  double cx = 0, cy = 0;  // principal point, pixels
  Mat3d R{1, 0, 0, 0, 1, 0, 0, 0, 1};  // world -> camera rotation, row-major
  Vec3d t;                             // world -> camera translation, mm
};

class PinholeCamera final : public CameraModel {
 public:
  explicit PinholeCamera(const PinholeParameters& p);

  // A camera yawed by `yaw_deg` about the world y axis (R of Eq. 3.12), looking at the world
  // origin from `distance_mm`, with the principal point at the image centre.
  static PinholeCamera yawed(double yaw_deg, double focal_length_mm, double pixel_pitch_um,
                             double distance_mm, int width, int height);

  const PinholeParameters& parameters() const { return p_; }
  Mat3d intrinsics() const;  // K, row-major
  Vec3d centre() const;      // projection centre in world mm

  std::string model_name() const override { return "pinhole"; }
  Vec2d project(const Vec3d& world) const override;
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  PinholeParameters p_;
};

}  // namespace tomorig::calibration
