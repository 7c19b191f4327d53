#pragma once
// Calibration targets: what a target looks like (its spec) and what detection found in one
// image of it at one known z. Detection never guesses: a point it cannot identify with
// certainty is dropped and named in `warnings`.
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "tomorig/core/geometry.h"
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

// How the dots of a dot target are arranged (docs/calibration.md, "Dot targets").
enum class DotLattice {
  square,     // dots at (i, j) * spacing
  staggered,  // also a second sub-lattice at (i + 1/2, j + 1/2) * spacing, possibly on a second
              // depth level: seen together, a square lattice turned 45 degrees whose
              // nearest-dot spacing is spacing / sqrt(2)
};

// A dot target with an origin marker: either a small hollow square framing the origin dot (as
// in ../shared/data/fluidimage-tomopiv), or a filled square in place of the origin dot. An
// optional filled triangle in place of a dot on the origin's level marks the +x axis (it lies
// at lattice site (k, 0), k > 0, of that level). Dots may be white on black or black on white.
// Axes without a triangle (the marker has no direction, so they follow the image, as fluidimage
// does): world +x is the lattice direction that points most nearly to the image's right (+u).
// In both cases world +y is the other lattice direction, pointing most nearly down the image
// (+v) when `y_down`, else up. Every camera must see the target from the same side. The dot at
// lattice step (i, j) from the origin is at world origin_mm + (i * spacing, j * spacing, 0) on
// the origin's level; a staggered target's second level is at origin_mm + ((i + 1/2) * spacing,
// (j + 1/2) * spacing, level_offset_mm).
struct DotGridSpec {
  // The pitch: distance of neighbouring dots of one level along x and y (the row pitch).
  double spacing_mm = 0;
  DotLattice lattice = DotLattice::square;
  double level_offset_mm = 0;  // staggered: z of the second level relative to the origin's
  Vec3d origin_mm;             // world position of the origin site (z adds to the plane z)
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
  // Where the origin and the unit steps along world +x and +y are in the image (px), for the
  // report and the overlay; unset for a chessboard.
  std::optional<Vec2d> origin_px, x_step_px, y_step_px;
  std::string origin_marker;  // "hollow square", "filled square"
  bool axis_marker = false;   // a triangle fixed +x
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
