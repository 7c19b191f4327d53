#pragma once
// The two-plane camera model ("twoplane"): a 2-D mapping per calibration plane z_k, and the
// line of sight through a pixel is the straight line through its back-projections onto the
// planes (least-squares line when there are more than two planes).
//
// Each plane holds two 2-D cubic polynomials in normalised coordinates (Appendix A.1), 20
// coefficients each (10 per output over [1, p, q, p^2, pq, q^2, p^3, p^2q, pq^2, q^3]):
//   to_world: (x~_I, y~_I) -> (x~, y~) on the plane, which defines the line of sight;
//   to_image: (x~, y~) -> (x~_I, y~_I), only the starting point of project()'s Newton solve.
#include <vector>

#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct TwoPlaneMapping {
  double z = 0;                   // world z of the plane, mm
  std::vector<double> to_world;  // 20 coefficients
  std::vector<double> to_image;  // 20 coefficients
};

class TwoPlaneCamera final : public CameraModel {
 public:
  static constexpr int kCoefficientsPerMapping = 20;

  // Throws tomorig::Error (bad_input) if there are fewer than 2 planes, two planes share a z,
  // a coefficient count is wrong or a value is not finite. Planes are kept sorted by z.
  TwoPlaneCamera(const Normalization& normalization, std::vector<TwoPlaneMapping> planes, int newton_steps = 4);

  const Normalization& normalization() const { return normalization_; }
  const std::vector<TwoPlaneMapping>& planes() const { return planes_; }
  int newton_steps() const { return newton_steps_; }

  std::string model_name() const override { return "twoplane"; }
  // Newton solve for the pixel whose line of sight passes through `world` (x, y at its z).
  Vec2d project(const Vec3d& world) const override;
  Vec3d back_project(const Vec2d& pixel, double world_z) const override;
  // Origin on the first plane's line, direction towards increasing world z.
  Ray line_of_sight(const Vec2d& pixel) const override;
  std::unique_ptr<CameraModel> clone() const override;

 private:
  Normalization normalization_;
  std::vector<TwoPlaneMapping> planes_;
  int newton_steps_;
};

}  // namespace tomorig::calibration
