#pragma once
// Pinhole camera (thesis Eq. 3.11): w [u v 1]^T = K [R | t] [x y z 1]^T.
//
// Camera frame: x_c to the right in the image, y_c downwards, z_c along the optical axis
// (away from the camera). So u grows with x_c and v with y_c, matching the pixel convention
// of camera_model.h. K = [[fx 0 cx] [0 fy cy] [0 0 1]], no skew, no distortion.
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
  // Throws tomorig::Error (bad_input) if fx or fy is not > 0 or R is not a rotation.
  explicit PinholeCamera(const PinholeParameters& p);

  // A camera yawed by `yaw_deg` about the world y axis (R of Eq. 3.12), looking at the world
  // origin from `distance_mm` (t = (0, 0, distance)), with the principal point at the image
  // centre ((W - 1) / 2, (H - 1) / 2) and fx = fy = focal length / pixel pitch.
  // Throws tomorig::Error (bad_input) naming the argument if a length or size is not > 0.
  static PinholeCamera yawed(double yaw_deg, double focal_length_mm, double pixel_pitch_um,
                             double distance_mm, int width, int height);

  const PinholeParameters& parameters() const { return p_; }
  Mat3d intrinsics() const;  // K, row-major
  Vec3d centre() const;      // projection centre in world mm: -R^T t

  // World point -> camera frame (mm); z is the depth along the optical axis.
  Vec3d to_camera(const Vec3d& world) const;
  // Lateral magnification (image size / object size) of a point at depth z_c on the axis:
  // f / z_c with f in mm; for a camera made by yawed(), magnification(origin) = f / D.
  double magnification(const Vec3d& world, double pixel_pitch_um) const;

  std::string model_name() const override { return "pinhole"; }
  Vec2d project(const Vec3d& world) const override;
  // Throws tomorig::Error (runtime) if the line of sight is parallel to the plane.
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  // Direction (not normalised) of the line of sight through `pixel`, in world coordinates.
  Vec3d world_direction(const Vec2d& pixel) const;

  PinholeParameters p_;
  Vec3d centre_;
};

}  // namespace tomorig::calibration
