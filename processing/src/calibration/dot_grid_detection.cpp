// detect_dot_grid: blobs and origin marker (dot_grid_blobs), lattice indices from the origin
// (dot_grid_lattice), then world = (i * spacing, j * spacing, z). See target_detection.h.
#include <cmath>

#include <fmt/core.h>

#include "dot_grid_blobs.h"
#include "dot_grid_lattice.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {

TargetDetection detect_dot_grid(const Image& image, const DotGridSpec& spec, double z_mm, const std::string& what) {
  if (!(spec.spacing_mm > 0) || !std::isfinite(spec.spacing_mm))
    throw bad_input(fmt::format("{}: dot grid spacing {} mm is invalid: it must be a positive number of mm", what,
                                spec.spacing_mm));
  if (!(spec.max_feature_px >= 0))
    throw bad_input(fmt::format("{}: max_feature_px {} is invalid: it must be >= 0 (0 = automatic)", what,
                                spec.max_feature_px));
  if (!std::isfinite(z_mm)) throw bad_input(fmt::format("{}: the plane position z is not a finite number", what));
  if (image.empty() || image.width() < 16 || image.height() < 16)
    throw bad_input(fmt::format("{}: the image is empty or smaller than 16 x 16 pixels", what));

  detail::DotBlobs blobs = detail::find_dot_blobs(image, spec.white_dots, spec.max_feature_px);
  const char* polarity = spec.white_dots ? "white dots on black" : "black dots on white";
  if (blobs.dots.size() < 3)
    throw bad_input(fmt::format("{}: no dot grid found ({} dot(s) of {}); check the polarity and that the target is "
                                "in view",
                                what, blobs.dots.size(), polarity));
  if (blobs.markers == 0)
    throw bad_input(fmt::format("{}: {} dots of {} found, but no origin marker (a square framing one dot); without it "
                                "no dot can be identified. Check that the origin is in view",
                                what, blobs.dots.size(), polarity));
  if (blobs.markers > 1)
    throw bad_input(fmt::format("{}: {} origin markers found; the origin is ambiguous, so no dot can be identified",
                                what, blobs.markers));

  const detail::Lattice lattice = detail::index_lattice(blobs.dots, *blobs.origin, spec.y_down);
  TargetDetection detection;
  for (const auto& w : blobs.warnings) detection.warnings.push_back(fmt::format("{}: {}", what, w));
  for (const auto& w : lattice.warnings) detection.warnings.push_back(fmt::format("{}: {}", what, w));
  detection.points.reserve(lattice.points.size());
  for (const detail::LatticePoint& p : lattice.points)
    detection.points.push_back({{p.i * spec.spacing_mm, p.j * spec.spacing_mm, z_mm}, blobs.dots[static_cast<std::size_t>(p.dot)]});
  return detection;
}

}  // namespace tomorig::calibration
