// detect_dot_grid: blobs and markers (dot_grid_blobs), lattice indices from the origin
// (dot_grid_lattice, dot_grid_staggered), the target's axes from the image or from the
// triangle marker, then world = origin + (i, j) * pitch on the level of the dot. See
// target_detection.h and docs/calibration.md, "Dot targets".
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/core.h>

#include "dot_grid_blobs.h"
#include "dot_grid_lattice.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {
namespace {

using detail::FoundMarker;
using detail::LatticePoint;
using detail::MarkerShape;

const char* shape_name(MarkerShape s) {
  switch (s) {
    case MarkerShape::hollow_square: return "hollow square";
    case MarkerShape::filled_square: return "filled square";
    case MarkerShape::triangle: return "triangle";
  }
  return "?";
}

std::string positions(const std::vector<FoundMarker>& markers) {
  std::string out;
  for (const FoundMarker& m : markers)
    out += fmt::format("{}{} at ({:.1f}, {:.1f}) px", out.empty() ? "" : ", ", shape_name(m.shape), m.centre.x, m.centre.y);
  return out;
}

// Lattice sites in some unit (pitch or half pitch) with the image steps per unit along +i, +j.
struct Indexed {
  std::vector<LatticePoint> points;
  std::vector<std::string> warnings;
  Vec2d ex, ey;
};

// One of the four lattice directions (+-i, +-j) as integer (di, dj).
struct Direction {
  int di = 0, dj = 0;
  Vec2d image(const Indexed& l) const { return {di * l.ex.x + dj * l.ey.x, di * l.ex.y + dj * l.ey.y}; }
};

}  // namespace

TargetDetection detect_dot_grid(const Image& image, const DotGridSpec& spec, double z_mm, const std::string& what) {
  if (!(spec.spacing_mm > 0) || !std::isfinite(spec.spacing_mm))
    throw bad_input(fmt::format("{}: dot grid spacing {} mm is invalid: it must be a positive number of mm", what,
                                spec.spacing_mm));
  if (!(spec.max_feature_px >= 0))
    throw bad_input(fmt::format("{}: max_feature_px {} is invalid: it must be >= 0 (0 = automatic)", what,
                                spec.max_feature_px));
  if (!std::isfinite(spec.level_offset_mm) || !std::isfinite(spec.origin_mm.x) || !std::isfinite(spec.origin_mm.y) ||
      !std::isfinite(spec.origin_mm.z))
    throw bad_input(fmt::format("{}: the target's level offset and origin must be finite numbers of mm", what));
  if (spec.lattice == DotLattice::square && spec.level_offset_mm != 0)
    throw bad_input(fmt::format("{}: a level offset of {} mm needs a staggered lattice (the second level's dots sit "
                                "between the first's); a square lattice has one level",
                                what, spec.level_offset_mm));
  if (!std::isfinite(z_mm)) throw bad_input(fmt::format("{}: the plane position z is not a finite number", what));
  if (image.empty() || image.width() < 16 || image.height() < 16)
    throw bad_input(fmt::format("{}: the image is empty or smaller than 16 x 16 pixels", what));

  detail::DotBlobs blobs = detail::find_dot_blobs(image, spec.white_dots, spec.max_feature_px);
  const char* polarity = spec.white_dots ? "white dots on black" : "black dots on white";
  if (blobs.dots.size() < 3)
    throw bad_input(fmt::format("{}: no dot grid found ({} dot(s) of {}); check the polarity and that the target is "
                                "in view",
                                what, blobs.dots.size(), polarity));
  std::vector<FoundMarker> origins, triangles;
  for (const FoundMarker& m : blobs.markers) (m.shape == MarkerShape::triangle ? triangles : origins).push_back(m);
  if (origins.empty())
    throw bad_input(fmt::format("{}: {} dots of {} found, but no origin marker (a hollow square framing one dot, or a "
                                "filled square in place of one){}; without it no dot can be identified. Check that the "
                                "origin is in view",
                                what, blobs.dots.size(), polarity,
                                triangles.empty() ? "" : fmt::format(" (found: {})", positions(triangles))));
  if (origins.size() > 1)
    throw bad_input(fmt::format("{}: {} origin markers found ({}); the origin is ambiguous, so no dot can be identified",
                                what, origins.size(), positions(origins)));
  if (triangles.size() > 1)
    throw bad_input(fmt::format("{}: {} triangle markers found ({}); one triangle marks +x, several make it ambiguous",
                                what, triangles.size(), positions(triangles)));

  // Filled markers stand in place of a dot: they take part in the indexing as sites, but their
  // centroids are not measured points.
  std::vector<Vec2d> sites = blobs.dots;
  const int real_dots = static_cast<int>(blobs.dots.size());
  int origin = origins.front().framed_dot;
  if (origin < 0) {
    origin = static_cast<int>(sites.size());
    sites.push_back(origins.front().centre);
  }
  int triangle = -1;
  if (!triangles.empty()) {
    triangle = static_cast<int>(sites.size());
    sites.push_back(triangles.front().centre);
  }

  Indexed lattice;
  const bool staggered = spec.lattice == DotLattice::staggered;
  if (staggered) {
    detail::StaggeredLattice s = detail::index_staggered(sites, origin);
    lattice = {std::move(s.points), std::move(s.warnings), s.ex, s.ey};
  } else {
    detail::Lattice l = detail::index_lattice(sites, origin, spec.y_down);
    lattice = {std::move(l.points), std::move(l.warnings), l.ex, l.ey};
  }
  // Unit of the indices: the pitch, or half of it on a staggered target.
  const double unit_mm = staggered ? 0.5 * spec.spacing_mm : spec.spacing_mm;
  const int pitch_units = staggered ? 2 : 1;

  TargetDetection detection;
  for (const auto& w : blobs.warnings) detection.warnings.push_back(fmt::format("{}: {}", what, w));
  for (const auto& w : lattice.warnings) detection.warnings.push_back(fmt::format("{}: {}", what, w));

  // The axes. +x: towards the triangle, else the lattice direction most nearly along +u.
  const std::array<Direction, 4> directions{Direction{1, 0}, Direction{-1, 0}, Direction{0, 1}, Direction{0, -1}};
  Direction x = directions[0];
  const auto triangle_site = std::find_if(lattice.points.begin(), lattice.points.end(),
                                          [&](const LatticePoint& p) { return p.dot == triangle; });
  if (triangle >= 0 && triangle_site != lattice.points.end()) {
    const int a = triangle_site->i, b = triangle_site->j;
    if (!staggered && a != 0 && std::abs(a) == std::abs(b))
      throw bad_input(fmt::format(
          "{}: the +x triangle marker at ({:.1f}, {:.1f}) px lies on a diagonal of the dot lattice (site ({}, {}) from "
          "the origin): the dots form a staggered lattice, turned 45 degrees to the target's axes, whose nearest-dot "
          "spacing is the row pitch / sqrt(2). Read as a square lattice, x and y would be turned by 45 degrees and "
          "scaled by sqrt(2). Describe it as staggered: --lattice staggered with --spacing = the row pitch (the "
          "distance between dots along x), or lattice = \"staggered\" and pitch_mm in --target-file",
          what, triangles.front().centre.x, triangles.front().centre.y, a, b));
    if ((a != 0 && b != 0) || (a % pitch_units) != 0 || (b % pitch_units) != 0)
      throw bad_input(fmt::format("{}: the +x triangle marker at ({:.1f}, {:.1f}) px is not on an axis of the origin's "
                                  "{}lattice (site ({}, {}){}); check the target description",
                                  what, triangles.front().centre.x, triangles.front().centre.y,
                                  staggered ? "sub-" : "", a, b, staggered ? " in half pitches" : ""));
    x = a != 0 ? Direction{a > 0 ? 1 : -1, 0} : Direction{0, b > 0 ? 1 : -1};
    detection.axis_marker = true;
  } else {
    if (triangle >= 0)
      detection.warnings.push_back(fmt::format("{}: the triangle marker at ({:.1f}, {:.1f}) px is not on the lattice "
                                               "grown from the origin; the axes follow the image",
                                               what, triangles.front().centre.x, triangles.front().centre.y));
    std::array<Direction, 4> sorted = directions;
    const auto along_u = [&](const Direction& d) {
      const Vec2d v = d.image(lattice);
      return v.x / std::hypot(v.x, v.y);
    };
    std::sort(sorted.begin(), sorted.end(), [&](const Direction& l, const Direction& r) { return along_u(l) > along_u(r); });
    x = sorted[0];
    if (along_u(sorted[0]) - along_u(sorted[1]) < 0.1)
      detection.warnings.push_back(fmt::format(
          "{}: the target's lattice is turned about 45 degrees in the image, so which lattice direction is +x is "
          "nearly ambiguous; check the axes of the result (a triangle marker on +x would fix them)",
          what));
  }
  // +y: perpendicular to x, down (or up) the image.
  Direction y{-x.dj, x.di};
  if ((y.image(lattice).y > 0) != spec.y_down) y = {-y.di, -y.dj};

  if (!staggered)
    if (const auto offset = detail::parity_offset(sites, lattice.points))
      throw bad_input(fmt::format(
          "{}: the dots form two interleaved sub-lattices, every other dot offset by ({:.2f}, {:.2f}) px from where "
          "one flat lattice puts it: a staggered plate with dots on two depth levels. Read as one square lattice, its "
          "nearest-dot spacing is the row pitch / sqrt(2) (x and y turned 45 degrees and scaled by sqrt(2)) and the two "
          "levels would be fitted as one plane. Describe it as staggered: --lattice staggered --spacing ROW_PITCH "
          "--level-offset MM, or lattice, pitch_mm and level_offset_mm in --target-file",
          what, offset->x, offset->y));

  int on_lattice = 0;
  for (const LatticePoint& p : lattice.points) {
    if (p.dot >= real_dots) continue;  // a filled marker
    ++on_lattice;
    const int i = p.i * x.di + p.j * x.dj, j = p.i * y.di + p.j * y.dj;
    const bool second_level = staggered && (p.i & 1);
    detection.points.push_back({{spec.origin_mm.x + i * unit_mm, spec.origin_mm.y + j * unit_mm,
                                 z_mm + spec.origin_mm.z + (second_level ? spec.level_offset_mm : 0.0)},
                                blobs.dots[static_cast<std::size_t>(p.dot)]});
  }
  if (const int unplaced = real_dots - on_lattice; unplaced > 0)
    detection.warnings.push_back(
        fmt::format("{}: {} dot(s) not on the lattice grown from the origin left out", what, unplaced));
  detection.origin_px = sites[static_cast<std::size_t>(origin)];
  const Vec2d xs = x.image(lattice), ys = y.image(lattice);
  detection.x_step_px = Vec2d{xs.x * pitch_units, xs.y * pitch_units};
  detection.y_step_px = Vec2d{ys.x * pitch_units, ys.y * pitch_units};
  detection.origin_marker = shape_name(origins.front().shape);
  return detection;
}

}  // namespace tomorig::calibration
