#pragma once
// Calibration targets: what a target looks like (its spec) and what detection found in one
// image of it at one known z. Detection never guesses: a point it cannot identify with
// certainty is dropped and named in `warnings`.
#include <string>
#include <variant>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

// A chessboard: `inner_corners_x` x `inner_corners_y` inner corners, `square_mm` apart. The
// world origin is the inner corner nearest the board's top-left square as seen by the camera
// unless the board carries no orientation cue; the spec then fixes orientation by convention
// (x along the longer side, see docs/calibration.md).
struct ChessboardSpec {
  int inner_corners_x = 0;
  int inner_corners_y = 0;
  double square_mm = 0;
};

// A regular dot grid with an origin marker (a small square framing the origin dot, as in
// ../shared/data/fluidimage-tomopiv). Dots may be white on black or black on white.
// Axes (the marker has no direction, so they follow the image, as fluidimage does): world +x
// is the lattice direction that points most nearly to the image's right (+u); world +y is the
// other lattice direction, pointing most nearly down the image (+v) when `y_down`, else up.
// Every camera must therefore see the target from the same side, without a large roll. The
// dot at lattice step (i, j) from the origin dot is at world (i * spacing, j * spacing, z).
struct DotGridSpec {
  double spacing_mm = 0;
  bool white_dots = true;
  bool y_down = true;
  // Dots and the marker must be smaller than this (pixels) so that the background estimate
  // (a grey-level opening) does not eat them; 0 = automatic (1/8 of the smaller image side).
  double max_feature_px = 0;
};

using TargetSpec = std::variant<ChessboardSpec, DotGridSpec>;

// The points found in one image of the target at plane height `z_mm`.
struct TargetDetection {
  std::vector<PointCorrespondence> points;  // world (mm, z = z_mm) and pixel
  std::vector<std::string> warnings;        // points dropped and why
};

// Both throw tomorig::Error (bad_input) naming `what` (e.g. "camera 2, plane z = -3 mm") when
// the target cannot be found at all.
TargetDetection detect_chessboard(const Image& image, const ChessboardSpec& spec, double z_mm,
                                  const std::string& what);
TargetDetection detect_dot_grid(const Image& image, const DotGridSpec& spec, double z_mm,
                                const std::string& what);

// Dispatches on the spec.
TargetDetection detect_target(const Image& image, const TargetSpec& spec, double z_mm,
                              const std::string& what);

}  // namespace tomorig::calibration
