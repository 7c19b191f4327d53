// Staggered dot targets: each sub-lattice grown with the pitch as step, and the parity test
// that recognises a staggered two-level target indexed as one square lattice.
#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>

#include <fmt/core.h>

#include "dot_grid_lattice.h"

namespace tomorig::calibration::detail {
namespace {

// Other-level dots sit ~0.71 pitch from a prediction (less the parallax); a site is ambiguous
// only with a second dot within 0.4 pitch, which tolerates a parallax of up to 0.3 pitch.
constexpr double kStaggeredAmbiguity = 0.4;

Vec2d sub(Vec2d a, Vec2d b) { return {a.x - b.x, a.y - b.y}; }
Vec2d add(Vec2d a, Vec2d b) { return {a.x + b.x, a.y + b.y}; }
Vec2d half(Vec2d a) { return {0.5 * a.x, 0.5 * a.y}; }
double norm(Vec2d a) { return std::hypot(a.x, a.y); }
double cross(Vec2d a, Vec2d b) { return a.x * b.y - a.y * b.x; }

}  // namespace

StaggeredLattice index_staggered(const std::vector<Vec2d>& dots, int origin) {
  StaggeredLattice out;
  out.points.push_back({origin, 0, 0});
  const Vec2d o = dots[static_cast<std::size_t>(origin)];
  // The four nearest dots are the other sub-lattice's at +-e1 + p and +-e2 + p (p: parallax);
  // half the difference of an opposite pair is the half-diagonal e free of p.
  std::vector<std::pair<double, int>> near;
  for (std::size_t k = 0; k < dots.size(); ++k)
    if (static_cast<int>(k) != origin) near.emplace_back(norm(sub(dots[k], o)), static_cast<int>(k));
  std::sort(near.begin(), near.end());
  if (near.size() < 4) {
    out.warnings.push_back("the origin has fewer than four neighbours; only the origin is identified");
    return out;
  }
  std::vector<int> four;
  for (int k = 0; k < 4; ++k) four.push_back(near[static_cast<std::size_t>(k)].second);
  std::sort(four.begin(), four.end(), [&](int a, int b) {
    const Vec2d da = sub(dots[static_cast<std::size_t>(a)], o), db = sub(dots[static_cast<std::size_t>(b)], o);
    return std::atan2(da.y, da.x) < std::atan2(db.y, db.x);
  });
  const auto at = [&](int k) { return dots[static_cast<std::size_t>(four[static_cast<std::size_t>(k)])]; };
  const Vec2d e1 = half(sub(at(0), at(2))), e2 = half(sub(at(1), at(3)));
  const double l1 = norm(e1), l2 = norm(e2);
  if (!(l1 > 0 && l2 > 0) || std::abs(cross(e1, e2)) < 0.7 * l1 * l2 || std::max(l1, l2) > 1.5 * std::min(l1, l2)) {
    out.warnings.push_back(fmt::format("the four dots nearest the origin at ({:.1f}, {:.1f}) px do not form the cell of a "
                                       "staggered lattice; only the origin is identified",
                                       o.x, o.y));
    return out;
  }
  // Pitch steps of each sub-lattice, and the same steps in half-pitch units.
  const Vec2d u = add(e1, e2), w = sub(e1, e2);
  out.ex = half(u);
  out.ey = half(w);

  const Lattice first = grow_lattice(dots, origin, u, w, kStaggeredAmbiguity);
  std::vector<bool> used(dots.size(), false);
  out.points.clear();
  for (const LatticePoint& p : first.points) {
    used[static_cast<std::size_t>(p.dot)] = true;
    out.points.push_back({p.dot, 2 * p.i, 2 * p.j});
  }
  out.warnings = first.warnings;
  // The second sub-lattice from the nearest dot at +e1 (site (1, 1) in half pitches).
  std::vector<Vec2d> rest;
  std::vector<int> index_of;
  int start = -1;
  for (std::size_t k = 0; k < dots.size(); ++k) {
    if (used[k]) continue;
    if (static_cast<int>(k) == four[0]) start = static_cast<int>(rest.size());
    rest.push_back(dots[k]);
    index_of.push_back(static_cast<int>(k));
  }
  if (start < 0) {
    out.warnings.push_back("the second sub-lattice's first dot was taken by the first; only the first is identified");
    return out;
  }
  // e1 = (u + w) / 2 is the step to site (1, 1); relative to that start the sub-lattice has
  // the same steps.
  const Lattice second = grow_lattice(rest, start, u, w, kStaggeredAmbiguity);
  for (const LatticePoint& p : second.points)
    out.points.push_back({index_of[static_cast<std::size_t>(p.dot)], 2 * p.i + 1, 2 * p.j + 1});
  out.warnings.insert(out.warnings.end(), second.warnings.begin(), second.warnings.end());
  return out;
}

std::optional<Vec2d> parity_offset(const std::vector<Vec2d>& dots, const std::vector<LatticePoint>& points) {
  std::map<std::pair<int, int>, Vec2d> at;
  for (const LatticePoint& p : points) at[{p.i, p.j}] = dots[static_cast<std::size_t>(p.dot)];
  double n[2] = {}, sx[2] = {}, sy[2] = {}, sxx[2] = {}, syy[2] = {};
  for (const auto& [site, pixel] : at) {
    const auto [i, j] = site;
    const auto a = at.find({i + 1, j}), b = at.find({i - 1, j}), c = at.find({i, j + 1}), d = at.find({i, j - 1});
    if (a == at.end() || b == at.end() || c == at.end() || d == at.end()) continue;
    const double rx = pixel.x - 0.25 * (a->second.x + b->second.x + c->second.x + d->second.x);
    const double ry = pixel.y - 0.25 * (a->second.y + b->second.y + c->second.y + d->second.y);
    const int parity = (i + j) & 1;
    n[parity] += 1, sx[parity] += rx, sy[parity] += ry, sxx[parity] += rx * rx, syy[parity] += ry * ry;
  }
  if (n[0] < 4 || n[1] < 4) return std::nullopt;
  double mx[2], my[2], var = 0;
  for (int k = 0; k < 2; ++k) {
    mx[k] = sx[k] / n[k];
    my[k] = sy[k] / n[k];
    var += (sxx[k] / n[k] - mx[k] * mx[k] + syy[k] / n[k] - my[k] * my[k]) / (2 * n[k]);
  }
  // A site's residual is -p on one level and +p on the other: the difference of the means is 2p.
  const Vec2d offset{0.5 * (mx[1] - mx[0]), 0.5 * (my[1] - my[0])};
  const double standard_error = 0.5 * std::sqrt(std::max(var, 0.0));
  if (norm(offset) > 0.15 && norm(offset) > 6 * standard_error) return offset;
  return std::nullopt;
}

}  // namespace tomorig::calibration::detail
