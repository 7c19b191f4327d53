#pragma once
// Second stage of dot-grid detection: integer lattice indices (i, j) for dot centres, counted
// from the origin dot, by growing the lattice outwards with local neighbour vectors (so that
// perspective and lens distortion, which change the spacing across the image, are followed).
#include <optional>
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
  Vec2d ex, ey;                       // the image steps along +i and +j at the origin (px)
};

// `y_down`: world +y is the lattice direction pointing most nearly down the image (else up).
// Dots left off the lattice are not reported (the caller knows which should have been on it).
// Throws nothing; a lattice that cannot be started (the origin dot has no two independent
// neighbours) comes back with the origin alone and a warning.
Lattice index_lattice(const std::vector<Vec2d>& dots, int origin, bool y_down);

// Grows the lattice from `origin` with the given start steps `ex`, `ey` (px), as index_lattice
// does after choosing them. A site with a second dot within `ambiguity` (a fraction of the
// local spacing) of its prediction is dropped. Dots left off the lattice are not reported
// (the caller knows which of them should have been on it).
Lattice grow_lattice(const std::vector<Vec2d>& dots, int origin, Vec2d ex, Vec2d ey, double ambiguity);

}  // namespace tomorig::calibration::detail

namespace tomorig::calibration::detail {

// A staggered target (two interleaved square sub-lattices, the second at the cell centres of
// the first, possibly on another depth level): sites in half-pitch units, (I, J) both even on
// the origin's sub-lattice, both odd on the other. Each sub-lattice is grown on its own with
// the pitch as step, so a parallax between the levels (the second level seen shifted in an
// oblique view) does not break the growth as it would on the 45-degree nearest-dot lattice.
struct StaggeredLattice {
  std::vector<LatticePoint> points;  // i, j = I, J in half-pitch units
  std::vector<std::string> warnings;
  Vec2d ex, ey;                      // image steps per half pitch along +I and +J at the origin
};
StaggeredLattice index_staggered(const std::vector<Vec2d>& dots, int origin);

// On a lattice indexed as one square lattice: the mean offset (px) of the sites with i + j odd
// against those with i + j even, each measured from the mean of its four neighbours, if it is
// clearly above the scatter (> 0.15 px and 6 standard errors). A target whose dots alternate
// between two depth levels shows it in any oblique view; a flat target does not.
std::optional<Vec2d> parity_offset(const std::vector<Vec2d>& dots, const std::vector<LatticePoint>& points);

}  // namespace tomorig::calibration::detail
