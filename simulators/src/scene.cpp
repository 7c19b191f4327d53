#include "tomorig/simulators/scene.h"

#include <random>

#include "tomorig/simulators/random.h"

namespace tomorig::sim {

std::vector<Vec3d> uniform_particles(const Slab& slab, std::size_t count, std::uint64_t seed) {
  std::mt19937_64 engine(seed);
  const Vec3d size = slab.size();
  std::vector<Vec3d> points(count);
  for (Vec3d& p : points) {
    p.x = slab.min.x + size.x * unit_double(engine);
    p.y = slab.min.y + size.y * unit_double(engine);
    p.z = slab.min.z + size.z * unit_double(engine);
  }
  return points;
}

}  // namespace tomorig::sim
