#include "tomorig/simulators/taylor_green.h"

#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::sim {

TaylorGreenFlow::TaylorGreenFlow(const VoxelGrid& grid, double amplitude_voxel, double period_voxel)
    : grid_(grid), amplitude_(amplitude_voxel), period_(period_voxel) {
  if (!(period_voxel > 0)) throw bad_input(fmt::format("taylor-green flow: period {} voxel must be > 0", period_voxel));
  if (!(grid.voxel_size > 0))
    throw bad_input(fmt::format("taylor-green flow: voxel size {} mm must be > 0", grid.voxel_size));
  if (!std::isfinite(amplitude_voxel)) throw bad_input("taylor-green flow: amplitude must be finite");
}

std::string TaylorGreenFlow::parameters_json() const {
  // Everything needed to evaluate Eq. 3.13 at a world point: x_vox = (X - origin) / voxel_size.
  return fmt::format(
      R"({{"equation":"thesis Eq. 3.13","A_voxel":{},"p_voxel":{},"voxel_size_mm":{},)"
      R"("grid":[{},{},{}],"grid_origin_mm":[{},{},{}],"units":"displacement in mm, A and p in voxel"}})",
      amplitude_, period_, grid_.voxel_size, grid_.nx, grid_.ny, grid_.nz, grid_.origin.x, grid_.origin.y,
      grid_.origin.z);
}

Vec3d TaylorGreenFlow::displacement_voxel(const Vec3d& voxel) const {
  const double k = 2.0 * std::numbers::pi / period_;
  const double sx = std::sin(k * voxel.x), cx = std::cos(k * voxel.x);
  const double sz = std::sin(k * voxel.z), cz = std::cos(k * voxel.z);
  return {amplitude_ * sx * cz, -amplitude_ * sx * sz, -amplitude_ * cx * sz};
}

Vec3d TaylorGreenFlow::displacement(const Vec3d& world) const {
  return displacement_voxel(grid_.voxel_of(world)) * grid_.voxel_size;
}

}  // namespace tomorig::sim
