#include "tomorig/processing/calibration/fit_camera_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "model_fits.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {

const std::vector<std::string>& camera_model_names() {
  static const std::vector<std::string> names{"pinhole", "dlt", "pinhole_distortion", "twoplane",
                                                "rational2", "soloff3"};
  return names;
}

const std::vector<std::string>& all_camera_model_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = camera_model_names();
    all.insert(all.begin() + 3, "refractive");
    return all;
  }();
  return names;
}

void measure_residuals(const CameraModel& model, std::span<const PointCorrespondence> points, FitReport& report) {
  report.points = static_cast<int>(points.size());
  report.planes = static_cast<int>(detail::group_by_plane(points).size());
  double forward_sum = 0, reverse_sum = 0, forward_squares = 0, reverse_squares = 0;
  report.forward_max_px = report.reverse_max_um = 0;
  for (const auto& p : points) {
    const Vec2d u = model.project(p.world);
    const double forward = std::hypot(u.x - p.pixel.x, u.y - p.pixel.y);
    const double reverse = 1000.0 * (model.back_project(p.pixel, p.world.z) - p.world).norm();
    forward_sum += forward;
    reverse_sum += reverse;
    forward_squares += forward * forward;
    reverse_squares += reverse * reverse;
    report.forward_max_px = std::max(report.forward_max_px, forward);
    report.reverse_max_um = std::max(report.reverse_max_um, reverse);
  }
  const double count = std::max<double>(1.0, static_cast<double>(points.size()));
  report.forward_mean_px = forward_sum / count;
  report.reverse_mean_um = reverse_sum / count;
  report.forward_rms_px = std::sqrt(forward_squares / count);
  report.reverse_rms_um = std::sqrt(reverse_squares / count);
}

namespace {

std::unique_ptr<CameraModel> fit_by_name(std::string_view model_name, std::span<const PointCorrespondence> points,
                                         const FitOptions& options, FitReport& report) {
  if (model_name == "dlt") return detail::fit_dlt(points, options, report);
  if (model_name == "pinhole") return detail::fit_pinhole(points, options, report);
  if (model_name == "pinhole_distortion") return detail::fit_lens(points, options, report);
  if (model_name == "refractive") return detail::fit_refractive(points, options, report);
  if (model_name == "rational2") return detail::fit_polynomial(PolynomialKind::rational2, points, options, report);
  if (model_name == "soloff3") return detail::fit_polynomial(PolynomialKind::soloff3, points, options, report);
  if (model_name == "twoplane") return detail::fit_two_plane(points, options, report);
  std::string known;
  for (const auto& name : all_camera_model_names()) known += (known.empty() ? "" : ", ") + name;
  throw bad_input(fmt::format("{}: unknown camera model '{}'; known models: {}", options.camera, model_name, known));
}

}  // namespace

std::unique_ptr<CameraModel> fit_camera_model(std::string_view model_name, std::span<const PointCorrespondence> points,
                                              ImageSize image_size, const FitOptions& options, FitReport& report) {
  report = FitReport{};
  report.model = std::string(model_name);
  report.camera = options.camera;
  if (image_size.width <= 0 || image_size.height <= 0)
    throw bad_input(fmt::format("{}: image size {} x {} is invalid: width and height must be > 0", options.camera,
                                image_size.width, image_size.height));
  // First attempt without giving up on non-convergence; a fit that ran out of iterations
  // gets retry_factor times as many before it fails (issue 18: rational2 walks a flat valley
  // on noisy distortion-free data and occasionally needs more than the default).
  FitOptions attempt = options;
  attempt.require_convergence = false;
  std::unique_ptr<CameraModel> model = fit_by_name(model_name, points, attempt, report);
  if (!report.converged && options.retry_factor > 1) {
    attempt.max_iterations = static_cast<int>(
        std::min<long long>(std::numeric_limits<int>::max(), 1LL * options.max_iterations * options.retry_factor));
    FitReport second = report;
    second.iterations = 0;
    model = fit_by_name(model_name, points, attempt, second);
    second.retry = fmt::format("{} on a second attempt with {} iterations", second.converged ? "converged" : "not converged",
                               attempt.max_iterations);
    report = second;
  }
  if (!report.converged && options.require_convergence)
    throw runtime_error(fmt::format("{}: the {} fit did not converge in {} iterations{}; check the correspondences for "
                                    "outliers, or allow more iterations (--max-iterations on the command line, "
                                    "FitOptions::max_iterations in code){}",
                                    options.camera, model_name, options.max_iterations,
                                    options.retry_factor > 1 ? fmt::format(", nor in {} on a second attempt", attempt.max_iterations)
                                                             : std::string(),
                                    model_name == "refractive" && options.fit_window_pose
                                        ? "; points at few depths (planes or lines) barely determine the window's pose: "
                                          "measure it, give it (--window-face, --window-normal) and keep it (--fix-window, "
                                          "FitOptions::fit_window_pose = false)"
                                        : ""));
  measure_residuals(*model, points, report);
  return model;
}

}  // namespace tomorig::calibration
