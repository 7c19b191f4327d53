#pragma once
// The planar Taylor-Green vortices with helical y displacement of thesis Eq. 3.13, defined in
// voxel units of a reconstruction grid (x = i, y = j, z = k of the grid):
//   dX =  A sin(2 pi x / p) cos(2 pi z / p)
//   dY = -A sin(2 pi x / p) sin(2 pi z / p)
//   dZ = -A cos(2 pi x / p) sin(2 pi z / p)
// The displacement is returned in mm (voxel displacement x voxel size).
#include "tomorig/core/volume.h"
#include "tomorig/simulators/flow.h"

namespace tomorig::sim {

class TaylorGreenFlow final : public Flow {
 public:
  // Throws tomorig::Error (bad_input) if the period or the voxel size is not > 0.
  TaylorGreenFlow(const VoxelGrid& grid, double amplitude_voxel, double period_voxel);

  std::string name() const override { return "taylor-green"; }
  std::string parameters_json() const override;
  Vec3d displacement(const Vec3d& world) const override;
  // The same field in voxel units at continuous voxel coordinates (x = i, z = k).
  Vec3d displacement_voxel(const Vec3d& voxel) const;

  double amplitude_voxel() const { return amplitude_; }
  double period_voxel() const { return period_; }
  const VoxelGrid& grid() const { return grid_; }

 private:
  VoxelGrid grid_;
  double amplitude_;
  double period_;
};

}  // namespace tomorig::sim
