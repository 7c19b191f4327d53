#pragma once
// Internal to the chessboard detector: growing a lattice of X-corners from a seed, so that
// every corner gets integer lattice coordinates (i, j) relative to the seed.
#include <map>
#include <utility>
#include <vector>

#include "chessboard_corners.h"

namespace tomorig::calibration::chessboard {

struct LatticeNode {
  Vec2d pixel;
  int polarity = 0;
};

// (i, j) -> node; i and j are relative to the seed corner (0, 0) and follow the two lattice
// directions found at the seed.
using Lattice = std::map<std::pair<int, int>, LatticeNode>;

// Grows lattices from seeds near the candidates' centroid and returns the largest. A corner
// joins only if it lies where its neighbours predict (within a fraction of a square) and has
// the polarity opposite to theirs, so stray saddles and the board's outer L-corners stay out.
Lattice grow_lattice(const GreyImage& grey, const std::vector<Candidate>& candidates);

}  // namespace tomorig::calibration::chessboard
