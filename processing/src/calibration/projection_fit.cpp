#include "projection_fit.h"

#include <limits>
#include <vector>

#include "tomorig/core/error.h"

namespace tomorig::calibration::detail {

LmResult fit_projection(std::span<const PointCorrespondence> points, double image_scale, const ProjectPoints& project,
                        Eigen::VectorXd& p, const LmSettings& settings) {
  const int count = static_cast<int>(points.size());
  std::vector<Vec2d> pixels(points.size());
  const ResidualFunction residuals = [&](const Eigen::VectorXd& q, Eigen::VectorXd& r, Eigen::MatrixXd* J) {
    r.resize(2 * count);
    try {
      project(q, pixels);
      for (int i = 0; i < count; ++i) {
        r(2 * i) = (pixels[i].x - points[i].pixel.x) / image_scale;
        r(2 * i + 1) = (pixels[i].y - points[i].pixel.y) / image_scale;
      }
    } catch (const Error&) {
      // Parameters outside the model's domain: an infinite cost, never accepted as a step.
      r.setConstant(std::numeric_limits<double>::quiet_NaN());
    }
    if (J) numeric_jacobian(residuals, q, 2 * count, *J);
  };
  return levenberg_marquardt(residuals, 2 * count, p, settings);
}

}  // namespace tomorig::calibration::detail
