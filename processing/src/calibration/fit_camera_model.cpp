#include "tomorig/processing/calibration/fit_camera_model.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "model_fits.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {

const std::vector<std::string>& camera_model_names() {
  static const std::vector<std::string> names{"pinhole", "dlt", "twoplane", "rational2", "soloff3"};
  return names;
}

void measure_residuals(const CameraModel& model, std::span<const PointCorrespondence> points, FitReport& report) {
  report.points = static_cast<int>(points.size());
  report.planes = static_cast<int>(detail::group_by_plane(points).size());
  double forward_sum = 0, reverse_sum = 0;
  report.forward_max_px = report.reverse_max_um = 0;
  for (const auto& p : points) {
    const Vec2d u = model.project(p.world);
    const double forward = std::hypot(u.x - p.pixel.x, u.y - p.pixel.y);
    const double reverse = 1000.0 * (model.back_project(p.pixel, p.world.z) - p.world).norm();
    forward_sum += forward;
    reverse_sum += reverse;
    report.forward_max_px = std::max(report.forward_max_px, forward);
    report.reverse_max_um = std::max(report.reverse_max_um, reverse);
  }
  const double count = std::max<double>(1.0, static_cast<double>(points.size()));
  report.forward_mean_px = forward_sum / count;
  report.reverse_mean_um = reverse_sum / count;
}

std::unique_ptr<CameraModel> fit_camera_model(std::string_view model_name, std::span<const PointCorrespondence> points,
                                              ImageSize image_size, const FitOptions& options, FitReport& report) {
  report = FitReport{};
  report.model = std::string(model_name);
  report.camera = options.camera;
  if (image_size.width <= 0 || image_size.height <= 0)
    throw bad_input(fmt::format("{}: image size {} x {} is invalid: width and height must be > 0", options.camera,
                                image_size.width, image_size.height));
  std::unique_ptr<CameraModel> model;
  if (model_name == "dlt") model = detail::fit_dlt(points, options, report);
  else if (model_name == "pinhole") model = detail::fit_pinhole(points, options, report);
  else if (model_name == "rational2") model = detail::fit_polynomial(PolynomialKind::rational2, points, options, report);
  else if (model_name == "soloff3") model = detail::fit_polynomial(PolynomialKind::soloff3, points, options, report);
  else if (model_name == "twoplane") model = detail::fit_two_plane(points, options, report);
  else {
    std::string known;
    for (const auto& name : camera_model_names()) known += (known.empty() ? "" : ", ") + name;
    throw bad_input(fmt::format("{}: unknown camera model '{}'; known models: {}", options.camera, model_name, known));
  }
  measure_residuals(*model, points, report);
  return model;
}

}  // namespace tomorig::calibration
