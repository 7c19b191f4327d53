#pragma once
// Flows: the displacement of a tracer between exposures A and B. A flow is independent of the
// scene and the cameras, so any case can pair any scene with any flow.
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::sim {

class Flow {
 public:
  virtual ~Flow() = default;
  // Short name recorded with the truth, e.g. "taylor-green".
  virtual std::string name() const = 0;
  // The parameters as a JSON object text, recorded with the truth so a reader can evaluate
  // the reference field without this code, e.g. {"A_voxel":5,"p_voxel":256,...}.
  virtual std::string parameters_json() const = 0;
  // Displacement (mm) from exposure A to exposure B of a tracer whose mid-time position is
  // `world` (mm).
  virtual Vec3d displacement(const Vec3d& world) const = 0;
};

// Positions at exposures A and B of tracers whose mid-time positions are `midpoints`.
struct ParticlePair {
  std::vector<Vec3d> a;
  std::vector<Vec3d> b;
};

// Central straddling: a = X - dX(X)/2, b = X + dX(X)/2, so (a + b)/2 = X and b - a = dX(X),
// i.e. the reference displacement at X is the flow evaluated at X (benchmarks/README).
ParticlePair straddle(std::span<const Vec3d> midpoints, const Flow& flow);

}  // namespace tomorig::sim
