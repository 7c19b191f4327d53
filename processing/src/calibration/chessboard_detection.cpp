// detect_chessboard: X-corner candidates -> lattice growth -> identification of each lattice
// corner with a board corner -> sub-pixel refinement.
//
// Orientation convention (docs/calibration.md, "Chessboard targets"): the board's x axis is the
// lattice axis with `inner_corners_x` corners when the whole board is seen and the counts tell
// the axes apart; otherwise it is the lattice axis closer to the image's horizontal. x points
// towards increasing u (image right); y completes an unmirrored frame, so for an upright view
// it points towards increasing v (image down), and the origin is the inner corner nearest the
// image's top-left. World z (the plane height passed in) then points away from the camera,
// as in PinholeCamera (x_c right, y_c down, z_c along the view).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "chessboard_corners.h"
#include "chessboard_lattice.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {

namespace {

using chessboard::Lattice;
using chessboard::operator+;
using chessboard::operator-;
using chessboard::operator*;
using chessboard::length;

// Mean step between lattice neighbours along i (axis 0) or j (axis 1).
Vec2d mean_step(const Lattice& l, int axis) {
  Vec2d sum{0, 0};
  int n = 0;
  for (const auto& [ij, node] : l) {
    const std::pair<int, int> next = axis == 0 ? std::pair{ij.first + 1, ij.second} : std::pair{ij.first, ij.second + 1};
    const auto it = l.find(next);
    if (it == l.end()) continue;
    sum = sum + (it->second.pixel - node.pixel);
    ++n;
  }
  return n ? (1.0 / n) * sum : Vec2d{0, 0};
}

// Whether the lattice ends at one end of an axis because the image border cuts it, rather
// than at the board's own edge. Evidence of the board edge: the position one step beyond the
// extreme corners lies well inside the image, yet no corner was found there. The end counts as
// the board edge if that holds for at least half of the extreme corners (and at least one).
bool cut_by_image(const Lattice& l, const chessboard::GreyImage& g, bool along_i, int extreme, int dir,
                  const Vec2d& fallback_step) {
  int extremes = 0, inside = 0;
  for (const auto& [ij, node] : l) {
    if ((along_i ? ij.first : ij.second) != extreme) continue;
    ++extremes;
    Vec2d step = double(dir) * fallback_step;
    const std::pair<int, int> behind = along_i ? std::pair{ij.first - dir, ij.second} : std::pair{ij.first, ij.second - dir};
    if (const auto it = l.find(behind); it != l.end()) step = node.pixel - it->second.pixel;
    const Vec2d beyond = node.pixel + step;
    const double margin = 0.45 * length(step) + 2;  // where a corner could still be found
    if (beyond.x >= margin && beyond.y >= margin && beyond.x <= g.width - 1 - margin && beyond.y <= g.height - 1 - margin)
      ++inside;
  }
  return !(inside >= 1 && 2 * inside >= extremes);
}

}  // namespace

TargetDetection detect_chessboard(const Image& image, const ChessboardSpec& spec, double z_mm,
                                  const std::string& what) {
  if (spec.inner_corners_x < 2 || spec.inner_corners_y < 2 || !(spec.square_mm > 0))
    throw bad_input(fmt::format("{}: chessboard spec {} x {} inner corners at {} mm: needs at least 2 x 2 corners "
                                "and a square size > 0",
                                what, spec.inner_corners_x, spec.inner_corners_y, spec.square_mm));
  if (!std::isfinite(z_mm)) throw bad_input(fmt::format("{}: plane z is not finite", what));
  const chessboard::GreyImage grey = chessboard::normalised_grey(image);
  double spacing = 0;
  const std::vector<chessboard::Candidate> candidates = chessboard::find_x_corner_candidates(grey, spacing);
  const Lattice lattice = chessboard::grow_lattice(grey, candidates);
  if (lattice.size() < 4)
    throw bad_input(fmt::format("{}: no chessboard found ({} X-corner candidates, largest lattice {} corners); "
                                "check the target spec, focus and exposure",
                                what, candidates.size(), lattice.size()));

  int imin = std::numeric_limits<int>::max(), imax = std::numeric_limits<int>::min(), jmin = imin, jmax = imax;
  for (const auto& [ij, node] : lattice) {
    imin = std::min(imin, ij.first), imax = std::max(imax, ij.first);
    jmin = std::min(jmin, ij.second), jmax = std::max(jmax, ij.second);
  }
  const int count_i = imax - imin + 1, count_j = jmax - jmin + 1;
  const int nx = spec.inner_corners_x, ny = spec.inner_corners_y;
  const Vec2d step_i = mean_step(lattice, 0), step_j = mean_step(lattice, 1);

  // Which lattice axis is the board's x axis.
  const bool fits_i = count_i <= nx && count_j <= ny, fits_j = count_j <= nx && count_i <= ny;
  const bool whole_i = count_i == nx && count_j == ny, whole_j = count_j == nx && count_i == ny;
  bool i_is_x;
  if (!fits_i && !fits_j)
    throw bad_input(fmt::format("{}: found a lattice of {} x {} corners, more than the spec's {} x {} inner corners; "
                                "check chessboard.inner_corners",
                                what, count_i, count_j, nx, ny));
  if (whole_i != whole_j) i_is_x = whole_i;
  else if (fits_i != fits_j) i_is_x = fits_i;
  else i_is_x = std::abs(step_i.x) / length(step_i) >= std::abs(step_j.x) / length(step_j);

  const Vec2d x_step = i_is_x ? step_i : step_j, y_step = i_is_x ? step_j : step_i;
  // x towards image right (or down if the x axis is nearly vertical); y unmirrored.
  const bool horizontal = std::abs(x_step.x) >= 0.2 * length(x_step);
  const int x_sign = (horizontal ? x_step.x : x_step.y) >= 0 ? 1 : -1;
  const double cross = x_sign * (x_step.x * y_step.y - x_step.y * y_step.x);
  const int y_sign = cross >= 0 ? 1 : -1;

  // Board index offsets along each board axis: from the counts when whole, else from which
  // end of the lattice is the board's own edge rather than the image border.
  auto offset_for = [&](bool along_i, int sign, int n, std::string_view axis_name) -> int {
    const int lo = along_i ? imin : jmin, hi = along_i ? imax : jmax;
    const int count = hi - lo + 1;
    // Board index b = sign * lattice index + offset; board index 0 is at the lattice end `first`.
    const int first = sign > 0 ? lo : hi, last = sign > 0 ? hi : lo;
    const Vec2d step = along_i ? step_i : step_j;
    if (count == n) return -sign * first;
    const bool first_cut = cut_by_image(lattice, grey, along_i, first, -sign, step);
    const bool last_cut = cut_by_image(lattice, grey, along_i, last, sign, step);
    if (!first_cut && last_cut) return -sign * first;
    if (first_cut && !last_cut) return (n - 1) - sign * last;
    throw bad_input(fmt::format("{}: only {} of the board's {} corners along {} are visible and {}; "
                                "the corners cannot be identified (show one edge of the board, or the whole board)",
                                what, count, n, axis_name,
                                first_cut ? "both ends are cut by the image border" : "neither end is cut by the image border"));
  };
  // Lattice index along the x axis grows along x_step; x_sign says whether that is +x.
  const int x_offset = offset_for(i_is_x, x_sign, nx, "x");
  const int y_offset = offset_for(!i_is_x, y_sign, ny, "y");

  TargetDetection out;
  // The fit window stays inside the four squares around the corner: well short of the nearest
  // neighbour along the lattice axes and diagonals (perspective can shorten either).
  const double radius =
      std::clamp(0.55 * std::min({length(step_i), length(step_j), length(step_i + step_j), length(step_i - step_j)}),
                 2.0, 20.0);
  int refined_out = 0;
  for (const auto& [ij, node] : lattice) {
    const int li = i_is_x ? ij.first : ij.second, lj = i_is_x ? ij.second : ij.first;
    const int bx = x_sign * li + x_offset, by = y_sign * lj + y_offset;
    if (bx < 0 || bx >= nx || by < 0 || by >= ny) {
      out.warnings.push_back(fmt::format("{}: corner at pixel ({:.1f}, {:.1f}) falls outside the board after "
                                         "identification; dropped",
                                         what, node.pixel.x, node.pixel.y));
      continue;
    }
    Vec2d p = node.pixel;
    if (!chessboard::refine_corner(grey, p, step_i, step_j, radius)) {
      ++refined_out;
      out.warnings.push_back(fmt::format("{}: corner ({}, {}) near pixel ({:.1f}, {:.1f}) could not be refined "
                                         "to sub-pixel accuracy (too close to the image border?); dropped",
                                         what, bx, by, node.pixel.x, node.pixel.y));
      continue;
    }
    out.points.push_back({{bx * spec.square_mm, by * spec.square_mm, z_mm}, p});
  }
  const int expected = nx * ny;
  const int missing = expected - static_cast<int>(out.points.size()) - refined_out;
  if (missing > 0)
    out.warnings.push_back(fmt::format("{}: {} of the board's {} corners were not found (outside the image, "
                                       "occluded or not recognised); they are not used",
                                       what, missing, expected));
  // Keep a stable order: row by row (y), then x.
  std::sort(out.points.begin(), out.points.end(), [](const PointCorrespondence& a, const PointCorrespondence& b) {
    return a.world.y != b.world.y ? a.world.y < b.world.y : a.world.x < b.world.x;
  });
  if (out.points.empty())
    throw bad_input(fmt::format("{}: the chessboard was found but none of its corners could be refined", what));
  return out;
}

}  // namespace tomorig::calibration
