#include "tomorig/processing/calibration/fit_types.h"

#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::calibration {

Normalization compute_normalization(std::span<const PointCorrespondence> points) {
  if (points.empty()) throw bad_input("calibration: no point correspondences to normalise");
  Normalization n;
  const double count = static_cast<double>(points.size());
  Vec3d wc;
  Vec2d ic;
  for (const auto& pt : points) {
    wc = wc + pt.world * (1.0 / count);
    ic.x += pt.pixel.x / count;
    ic.y += pt.pixel.y / count;
  }
  double world_mean = 0, image_mean = 0;
  for (const auto& pt : points) {
    world_mean += (pt.world - wc).norm() / count;
    image_mean += std::hypot(pt.pixel.x - ic.x, pt.pixel.y - ic.y) / count;
  }
  if (!(world_mean > 0) || !(image_mean > 0))
    throw bad_input(fmt::format("calibration: all {} points coincide in the {}; they cannot be normalised", points.size(),
                                world_mean > 0 ? "image" : "world"));
  n.world_centre = wc;
  n.image_centre = ic;
  // Mean distance sqrt(3) and sqrt(2): the "average" point becomes (1, 1, 1) and (1, 1).
  n.world_scale = world_mean / std::numbers::sqrt3;
  n.image_scale = image_mean / std::numbers::sqrt2;
  return n;
}

std::string FitOptions::validate() const {
  if (max_iterations < 1) return fmt::format("max_iterations = {} is invalid: it must be >= 1", max_iterations);
  if (!(tolerance > 0) || !(tolerance < 1))
    return fmt::format("tolerance = {} is invalid: it must be in (0, 1)", tolerance);
  if (retry_factor < 1 || retry_factor > 100)
    return fmt::format("retry_factor = {} is invalid: it must be in [1, 100]", retry_factor);
  if (window)
    if (const std::string problem = window->validate(); !problem.empty()) return "window: " + problem;
  if (newton_steps < 0 || newton_steps > 50)
    return fmt::format("newton_steps = {} is invalid: it must be in [0, 50]", newton_steps);
  return {};
}

std::string FitReport::brief() const {
  std::string line = fmt::format("{} {}: {} points on {} planes, forward RMS {:.4f} px (mean {:.4f}, max {:.4f}), reverse "
                                 "RMS {:.3f} um (mean {:.3f}, max {:.3f})",
                                 camera, model, points, planes, forward_rms_px, forward_mean_px, forward_max_px,
                                 reverse_rms_um, reverse_mean_um, reverse_max_um);
  if (inverse_mapping_mean_um) line += fmt::format(" (inverse mapping alone {:.3f} um)", *inverse_mapping_mean_um);
  line += fmt::format(", {} iterations, {}", iterations, converged ? "converged" : "NOT converged");
  if (!retry.empty()) line += " (" + retry + ")";
  return line;
}

}  // namespace tomorig::calibration
