// Lattice growth for the chessboard detector.
#include "chessboard_lattice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <optional>

namespace tomorig::calibration::chessboard {

namespace {

struct Seed {
  Vec2d step_i, step_j;
};

// The indices of the candidates nearest to p, closest first (at most `count`).
std::vector<std::size_t> nearest(const std::vector<Candidate>& c, const Vec2d& p, std::size_t count) {
  std::vector<std::pair<double, std::size_t>> d;
  d.reserve(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) d.emplace_back(length(c[k].pixel - p), k);
  count = std::min(count, d.size());
  std::partial_sort(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(count), d.end());
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < count; ++k) out.push_back(d[k].second);
  return out;
}

// Two pairs of opposite neighbours around candidate `s` give the lattice steps there.
std::optional<Seed> seed_steps(const std::vector<Candidate>& c, std::size_t s) {
  const Vec2d p = c[s].pixel;
  std::vector<std::size_t> near = nearest(c, p, 9);
  near.erase(std::remove(near.begin(), near.end(), s), near.end());
  std::vector<Vec2d> axes;  // half of (q1 - q2) for each opposite pair, nearest pairs first
  for (std::size_t a = 0; a < near.size(); ++a)
    for (std::size_t b = a + 1; b < near.size(); ++b) {
      const Vec2d q1 = c[near[a]].pixel, q2 = c[near[b]].pixel;
      const double r = 0.5 * (length(q1 - p) + length(q2 - p));
      if (length(q1 + q2 - 2.0 * p) < 0.15 * r) axes.push_back(0.5 * (q1 - q2));
    }
  if (axes.size() < 2) return std::nullopt;
  const Vec2d a = axes[0];
  for (std::size_t k = 1; k < axes.size(); ++k) {
    const Vec2d b = axes[k];
    const double cosine = std::abs(dot(a, b)) / (length(a) * length(b));
    if (cosine < 0.7) return Seed{a, b};
  }
  return std::nullopt;
}

Lattice grow_from(const GreyImage& grey, const std::vector<Candidate>& c, std::size_t s, const Seed& seed,
                  std::vector<int>& owner) {
  std::fill(owner.begin(), owner.end(), 0);
  Lattice lattice;
  const int pol = corner_polarity(grey, c[s].pixel, seed.step_i, seed.step_j);
  if (pol == 0) return lattice;
  struct Work {
    std::pair<int, int> ij;
    Vec2d step_i, step_j;
  };
  lattice[{0, 0}] = {c[s].pixel, pol};
  owner[s] = 1;
  std::deque<Work> queue{{{0, 0}, seed.step_i, seed.step_j}};
  constexpr std::array<std::array<int, 2>, 4> dirs{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  while (!queue.empty()) {
    const Work w = queue.front();
    queue.pop_front();
    const LatticeNode here = lattice.at(w.ij);
    for (const auto& d : dirs) {
      const std::pair<int, int> next{w.ij.first + d[0], w.ij.second + d[1]};
      if (lattice.count(next)) continue;
      // Prefer extrapolating from the node behind: it follows the perspective change.
      Vec2d step = d[0] != 0 ? double(d[0]) * w.step_i : double(d[1]) * w.step_j;
      const auto behind = lattice.find({w.ij.first - d[0], w.ij.second - d[1]});
      if (behind != lattice.end()) step = here.pixel - behind->second.pixel;
      const Vec2d predicted = here.pixel + step;
      const double tolerance = 0.3 * length(step);
      std::size_t best = c.size();
      double best_d = tolerance;
      for (std::size_t k = 0; k < c.size(); ++k) {
        if (owner[k]) continue;
        const double dist = length(c[k].pixel - predicted);
        if (dist < best_d) best_d = dist, best = k;
      }
      if (best == c.size()) continue;
      const Vec2d found = c[best].pixel;
      Vec2d si = w.step_i, sj = w.step_j;
      if (d[0] != 0) si = double(d[0]) * (found - here.pixel);
      else sj = double(d[1]) * (found - here.pixel);
      const int p = corner_polarity(grey, found, si, sj);
      if (p != -here.polarity) continue;
      lattice[next] = {found, p};
      owner[best] = 1;
      queue.push_back({next, si, sj});
    }
  }
  return lattice;
}

}  // namespace

Lattice grow_lattice(const GreyImage& grey, const std::vector<Candidate>& candidates) {
  Lattice best;
  if (candidates.size() < 5) return best;
  Vec2d centroid{0, 0};
  for (const Candidate& k : candidates) centroid = centroid + k.pixel;
  centroid = (1.0 / static_cast<double>(candidates.size())) * centroid;
  const std::vector<std::size_t> order = nearest(candidates, centroid, candidates.size());
  std::vector<int> owner(candidates.size());
  int tried = 0;
  for (std::size_t s : order) {
    const std::optional<Seed> seed = seed_steps(candidates, s);
    if (!seed) continue;
    Lattice l = grow_from(grey, candidates, s, *seed, owner);
    if (l.size() > best.size()) best = std::move(l);
    // A seed whose lattice took most candidates is the board; others would find the same.
    if (best.size() * 2 > candidates.size() || ++tried >= 12) break;
  }
  return best;
}

}  // namespace tomorig::calibration::chessboard
