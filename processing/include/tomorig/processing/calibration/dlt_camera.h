#pragma once
// The direct linear transformation (thesis Eq. 2.1/2.2): w [u v 1]^T = A [x y z 1]^T with a
// 3 x 4 matrix A in physical units (mm -> pixels). A fitted DLT is estimated in normalised
// coordinates (Appendix A.1, A.2.1) and then denormalised, so evaluation needs no
// normalisation; the normalisation used is kept for the record.
#include <array>
#include <optional>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace tomorig::calibration {

// A row-major 3 x 4 matrix.
using Mat34d = std::array<double, 12>;

// A DLT matrix factored as K [R | t] (thesis Sect. 2.1.2). PinholeParameters has no skew, so
// the skew K(0,1) of the factorisation is given apart: it is ~0 for a real camera.
struct PinholeDecomposition {
  PinholeParameters parameters;
  double skew = 0;
};

class DltCamera final : public CameraModel {
 public:
  // Throws tomorig::Error (bad_input) if a coefficient is not finite or the left 3 x 3 block
  // is singular (no camera has it). The matrix is rescaled so that its third row has unit
  // norm and points into the scene (w > 0 in front of the camera).
  explicit DltCamera(const Mat34d& matrix, const Normalization& normalization = {});

  const Mat34d& matrix() const { return a_; }
  const Normalization& normalization() const { return normalization_; }
  // K [R | t] when the matrix is that of a right-handed camera; nullopt otherwise.
  std::optional<PinholeDecomposition> decompose() const;
  Vec3d centre() const { return centre_; }

  std::string model_name() const override { return "dlt"; }
  Vec2d project(const Vec3d& world) const override;
  // Throws tomorig::Error (runtime) if the line of sight is parallel to the plane.
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  // From the projection centre, pointing into the scene.
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  Vec3d world_direction(const Vec2d& pixel) const;

  Mat34d a_;
  Normalization normalization_;
  std::array<double, 9> m_inverse_;  // inverse of the left 3 x 3 block, row-major
  Vec3d centre_;
};

}  // namespace tomorig::calibration
