#include "tomorig/simulators/flow.h"

namespace tomorig::sim {

ParticlePair straddle(std::span<const Vec3d> midpoints, const Flow& flow) {
  ParticlePair pair;
  pair.a.resize(midpoints.size());
  pair.b.resize(midpoints.size());
  for (std::size_t n = 0; n < midpoints.size(); ++n) {
    const Vec3d half = flow.displacement(midpoints[n]) * 0.5;
    pair.a[n] = midpoints[n] - half;
    pair.b[n] = midpoints[n] + half;
  }
  return pair;
}

}  // namespace tomorig::sim
