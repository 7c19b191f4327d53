#pragma once
// Scenes: where the tracers are at the mid-time of a double exposure. A scene knows nothing
// about flows or cameras; the flow (flow.h) moves the points, the renderer images them.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::sim {

// An axis-aligned box in world mm, e.g. the seeded slab of a light sheet.
struct Slab {
  Vec3d min;
  Vec3d max;
  bool contains(const Vec3d& p) const {
    return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z && p.z <= max.z;
  }
  Vec3d size() const { return max - min; }
  Vec3d centre() const { return (min + max) * 0.5; }
};

// `count` points uniformly random in `slab`, drawn from std::mt19937_64(seed) in the order
// x, y, z of particle 0, then particle 1, ... The same seed gives the same points everywhere.
std::vector<Vec3d> uniform_particles(const Slab& slab, std::size_t count, std::uint64_t seed);

}  // namespace tomorig::sim
