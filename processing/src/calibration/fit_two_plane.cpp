// The two-plane model: independent 2-D cubic mappings per calibration plane.
#include <algorithm>

#include <fmt/core.h>

#include "identifiability.h"
#include "mapping_fit.h"
#include "model_fits.h"
#include "tomorig/processing/calibration/two_plane_camera.h"

namespace tomorig::calibration::detail {

std::unique_ptr<CameraModel> fit_two_plane(std::span<const PointCorrespondence> points, const FitOptions& options,
                                           FitReport& report) {
  constexpr int kTerms = TwoPlaneCamera::kCoefficientsPerMapping / 2;
  const Normalization n = check_points(points, {"twoplane", 2 * kTerms, 2, kTerms}, options);
  const MapForm form{Basis::cubic_2d, false};
  std::vector<double> identity(2 * kTerms, 0.0);
  identity[1] = identity[kTerms + 2] = 1;  // first output follows p, second q

  std::vector<TwoPlaneMapping> mappings;
  report.iterations = 0;
  report.converged = true;
  for (const Plane& plane : group_by_plane(points)) {
    MapSamples to_world, to_image;
    for (const auto& p : plane.points) {
      const Vec3d w = n.to_normalised(p.world);
      const Vec2d i = n.to_normalised(p.pixel);
      to_world.inputs.push_back({i.x, i.y, 0});
      to_world.targets.push_back({w.x, w.y});
      to_image.inputs.push_back({w.x, w.y, 0});
      to_image.targets.push_back(i);
    }
    FitOptions plane_options = options;
    plane_options.camera = fmt::format("{}, plane z = {} mm", options.camera, plane.z);
    require_determined(Basis::cubic_2d, "twoplane", plane.points, compute_normalization(plane.points), plane_options);
    const MapFit world_fit = fit_map(form, to_world, identity, lm_settings(options));
    check_fit(world_fit.lm, 2 * kTerms, "twoplane", "plane mapping to world", plane_options);
    const MapFit image_fit = fit_map(form, to_image, identity, lm_settings(options));
    check_fit(image_fit.lm, 2 * kTerms, "twoplane", "plane mapping to image", plane_options);
    mappings.push_back({plane.z, world_fit.coefficients, image_fit.coefficients});
    report.iterations = std::max(report.iterations, world_fit.lm.iterations);
    report.converged = report.converged && world_fit.lm.converged && image_fit.lm.converged;
  }
  report.normalization = n;
  return std::make_unique<TwoPlaneCamera>(n, std::move(mappings), options.newton_steps);
}

}  // namespace tomorig::calibration::detail
