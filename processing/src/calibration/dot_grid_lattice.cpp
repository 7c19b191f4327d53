// Lattice indexing of dot centres. Starting at the origin dot with the two shortest
// independent neighbour vectors, every identified dot predicts its four lattice neighbours from
// its own local step vectors (measured from identified neighbours where they exist), so the
// prediction follows perspective and distortion across the image. A site is identified only if
// exactly one dot lies near its prediction; a site with two candidates, or a dot claimed by two
// sites, is dropped with a warning rather than resolved by a guess.
#include "dot_grid_lattice.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <utility>

#include <fmt/core.h>

namespace tomorig::calibration::detail {
namespace {

// A prediction is accepted within this fraction of the local spacing ...
constexpr double kAcceptRadius = 0.3;
// ... and only if no second dot lies within this fraction of it.
constexpr double kAmbiguityRadius = 0.5;

Vec2d operator+(Vec2d a, Vec2d b) { return {a.x + b.x, a.y + b.y}; }
Vec2d operator-(Vec2d a, Vec2d b) { return {a.x - b.x, a.y - b.y}; }
Vec2d operator*(double s, Vec2d a) { return {s * a.x, s * a.y}; }
double dot(Vec2d a, Vec2d b) { return a.x * b.x + a.y * b.y; }
double norm(Vec2d a) { return std::hypot(a.x, a.y); }
double cross(Vec2d a, Vec2d b) { return a.x * b.y - a.y * b.x; }

using Site = std::pair<int, int>;

struct Identified {
  int dot = 0;
  Vec2d ex, ey;  // local lattice steps along +i and +j (pixels)
};

// Dots within `radius` of `p`, nearest first.
std::vector<int> dots_near(const std::vector<Vec2d>& dots, Vec2d p, double radius) {
  std::vector<std::pair<double, int>> found;
  for (std::size_t k = 0; k < dots.size(); ++k)
    if (const double d = norm(dots[k] - p); d < radius) found.emplace_back(d, static_cast<int>(k));
  std::sort(found.begin(), found.end());
  std::vector<int> out;
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

// Gauss reduction of a 2-D lattice basis: the shortest basis of the lattice a, b span.
void reduce(Vec2d& a, Vec2d& b) {
  for (int guard = 0; guard < 32; ++guard) {
    if (norm(b) < norm(a)) std::swap(a, b);
    const double m = std::round(dot(a, b) / dot(a, a));
    if (m == 0) return;
    b = b - m * a;
  }
}

struct Basis {
  Vec2d ex, ey;
};

std::optional<Basis> start_basis(const std::vector<Vec2d>& dots, int origin, bool y_down) {
  const Vec2d o = dots[static_cast<std::size_t>(origin)];
  std::vector<std::pair<double, Vec2d>> neighbours;
  for (std::size_t k = 0; k < dots.size(); ++k)
    if (static_cast<int>(k) != origin) neighbours.emplace_back(norm(dots[k] - o), dots[k] - o);
  std::sort(neighbours.begin(), neighbours.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
  if (neighbours.size() < 2) return std::nullopt;
  Vec2d a = neighbours[0].second, b;
  bool found = false;
  for (std::size_t k = 1; k < neighbours.size() && neighbours[k].first < 4 * neighbours[0].first; ++k)
    if (std::abs(cross(a, neighbours[k].second)) > 0.5 * norm(a) * neighbours[k].first) {
      b = neighbours[k].second;
      found = true;
      break;
    }
  if (!found) return std::nullopt;
  reduce(a, b);
  // A step that skips a dot (its neighbours at +-v/2 both exist) is halved.
  for (Vec2d* v : {&a, &b}) {
    const double r = kAcceptRadius * std::min(norm(a), norm(b)) / 2;
    if (!dots_near(dots, o + 0.5 * *v, r).empty() && !dots_near(dots, o - 0.5 * *v, r).empty()) *v = 0.5 * *v;
  }
  reduce(a, b);
  // Measured from the dots on both sides where they exist: a target whose dots alternate
  // between two depth levels shifts every other dot by a parallax p, and the one-sided step
  // carries p while the half difference of the two sides does not.
  for (Vec2d* v : {&a, &b}) {
    const std::vector<int> ahead = dots_near(dots, o + *v, 0.5 * norm(*v)), behind = dots_near(dots, o - *v, 0.5 * norm(*v));
    if (!ahead.empty() && !behind.empty())
      *v = 0.5 * (dots[static_cast<std::size_t>(ahead[0])] - dots[static_cast<std::size_t>(behind[0])]);
  }

  Basis basis;
  // +x: the lattice direction most nearly along the image's +u.
  std::vector<Vec2d> candidates = {a, -1.0 * a, b, -1.0 * b};
  std::sort(candidates.begin(), candidates.end(), [](Vec2d l, Vec2d r) { return l.x / norm(l) > r.x / norm(r); });
  basis.ex = candidates[0];
  basis.ey = std::abs(cross(basis.ex, a)) > std::abs(cross(basis.ex, b)) ? a : b;
  if ((basis.ey.y > 0) != y_down) basis.ey = -1.0 * basis.ey;
  return basis;
}

}  // namespace

Lattice index_lattice(const std::vector<Vec2d>& dots, int origin, bool y_down) {
  const std::optional<Basis> basis = start_basis(dots, origin, y_down);
  if (!basis) {
    Lattice lattice;
    lattice.points.push_back({origin, 0, 0});
    lattice.warnings.push_back("the origin dot has no two independent neighbours; only the origin is identified");
    return lattice;
  }
  Lattice lattice = grow_lattice(dots, origin, basis->ex, basis->ey, kAmbiguityRadius);
  return lattice;
}

Lattice grow_lattice(const std::vector<Vec2d>& dots, int origin, Vec2d ex, Vec2d ey, double ambiguity) {
  Lattice lattice;
  lattice.ex = ex;
  lattice.ey = ey;
  std::map<Site, Identified> sites;
  std::set<Site> rejected;
  std::map<int, Site> owner;       // dot -> site
  std::set<int> conflicted_dots;
  sites[{0, 0}] = {origin, ex, ey};
  owner[origin] = {0, 0};
  std::deque<Site> queue = {{0, 0}};

  while (!queue.empty()) {
    const Site s = queue.front();
    queue.pop_front();
    const Identified here = sites.at(s);
    const Vec2d p = dots[static_cast<std::size_t>(here.dot)];
    for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const Site t{s.first + di, s.second + dj};
      if (sites.count(t) || rejected.count(t)) continue;
      Vec2d step = di != 0 ? static_cast<double>(di) * here.ex : static_cast<double>(dj) * here.ey;
      // The step two sites back along the same line joins sites of the same parities as this
      // one, so it follows a lattice whose every other dot is shifted (two-level targets).
      const auto back1 = sites.find({s.first - di, s.second - dj}), back2 = sites.find({s.first - 2 * di, s.second - 2 * dj});
      if (back1 != sites.end() && back2 != sites.end())
        step = dots[static_cast<std::size_t>(back1->second.dot)] - dots[static_cast<std::size_t>(back2->second.dot)];
      const Vec2d predicted = p + step;
      const double spacing = std::min(norm(here.ex), norm(here.ey));
      const std::vector<int> near = dots_near(dots, predicted, ambiguity * spacing);
      if (near.empty() || norm(dots[static_cast<std::size_t>(near[0])] - predicted) > kAcceptRadius * spacing) continue;
      if (near.size() > 1) {
        rejected.insert(t);
        lattice.warnings.push_back(fmt::format("lattice site ({}, {}) dropped: {} dots near its expected position "
                                               "({:.1f}, {:.1f}) px, none can be told apart",
                                               t.first, t.second, near.size(), predicted.x, predicted.y));
        continue;
      }
      const int d = near[0];
      if (const auto claimed = owner.find(d); claimed != owner.end()) {
        rejected.insert(t);
        conflicted_dots.insert(d);
        lattice.warnings.push_back(fmt::format("dot at ({:.1f}, {:.1f}) px dropped: it fits lattice sites ({}, {}) "
                                               "and ({}, {})",
                                               dots[static_cast<std::size_t>(d)].x, dots[static_cast<std::size_t>(d)].y,
                                               claimed->second.first, claimed->second.second, t.first, t.second));
        continue;
      }
      Identified next = here;
      const Vec2d measured = dots[static_cast<std::size_t>(d)] - p;
      if (di != 0) next.ex = static_cast<double>(di) * measured;
      else next.ey = static_cast<double>(dj) * measured;
      next.dot = d;
      // The other axis' step, measured where an identified neighbour allows.
      const Vec2d q = dots[static_cast<std::size_t>(d)];
      auto measured_step = [&](Site back, Site ahead, Vec2d fallback) {
        if (const auto b = sites.find(back); b != sites.end()) return q - dots[static_cast<std::size_t>(b->second.dot)];
        if (const auto a = sites.find(ahead); a != sites.end()) return dots[static_cast<std::size_t>(a->second.dot)] - q;
        return fallback;
      };
      if (di != 0) next.ey = measured_step({t.first, t.second - 1}, {t.first, t.second + 1}, next.ey);
      else next.ex = measured_step({t.first - 1, t.second}, {t.first + 1, t.second}, next.ex);
      sites[t] = next;
      owner[d] = t;
      queue.push_back(t);
    }
  }

  lattice.points.clear();
  for (const auto& [site, id] : sites)
    if (!conflicted_dots.count(id.dot)) lattice.points.push_back({id.dot, site.first, site.second});
  return lattice;
}

}  // namespace tomorig::calibration::detail
