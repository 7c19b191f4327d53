#pragma once
// Second stage of dot-grid detection: integer lattice indices (i, j) for dot centres, counted
// from the origin dot, by growing the lattice outwards with local neighbour vectors (so that
// perspective and lens distortion, which change the spacing across the image, are followed).
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::calibration::detail {

struct LatticePoint {
  int dot = 0;  // index into the dot list
  int i = 0, j = 0;
};

struct Lattice {
  std::vector<LatticePoint> points;
  std::vector<std::string> warnings;  // dots left out and why
};

// `y_down`: world +y is the lattice direction pointing most nearly down the image (else up).
// Throws nothing; a lattice that cannot be started (the origin dot has no two independent
// neighbours) comes back with the origin alone and a warning.
Lattice index_lattice(const std::vector<Vec2d>& dots, int origin, bool y_down);

}  // namespace tomorig::calibration::detail
