#pragma once
// Voxel grids and volumes. Index order: x fastest, then y, then z (linear = x + nx*(y + ny*z)).
// World coordinates are in mm; voxel (i, j, k) has its centre at origin + (i, j, k) * voxel_size.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig {

struct VoxelGrid {
  int nx = 0, ny = 0, nz = 0;
  Vec3d origin;             // world position (mm) of the centre of voxel (0, 0, 0)
  double voxel_size = 0.0;  // mm, isotropic

  std::size_t voxel_count() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  }
  Vec3d centre_of(double i, double j, double k) const {
    return {origin.x + i * voxel_size, origin.y + j * voxel_size, origin.z + k * voxel_size};
  }
  // Continuous voxel coordinates of a world point.
  Vec3d voxel_of(const Vec3d& world) const {
    return {(world.x - origin.x) / voxel_size, (world.y - origin.y) / voxel_size,
            (world.z - origin.z) / voxel_size};
  }
  std::size_t linear(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(nx) * (static_cast<std::size_t>(j) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(k));
  }
  // A grid of nx x ny x nz voxels centred on the world origin.
  static VoxelGrid centred(int nx, int ny, int nz, double voxel_size) {
    return {nx, ny, nz, {-(nx - 1) * 0.5 * voxel_size, -(ny - 1) * 0.5 * voxel_size, -(nz - 1) * 0.5 * voxel_size},
            voxel_size};
  }
};

// A dense float volume: every voxel stored.
struct DenseVolume {
  VoxelGrid grid;
  std::vector<float> values;  // grid.voxel_count() entries

  explicit DenseVolume(const VoxelGrid& g = {}) : grid(g), values(g.voxel_count(), 0.0f) {}
  float& at(int i, int j, int k) { return values[grid.linear(i, j, k)]; }
  float at(int i, int j, int k) const { return values[grid.linear(i, j, k)]; }
};

// A sparse volume: only active voxels, as a structure of arrays so that hot loops stream
// through contiguous memory. Indices are linear indices into `grid` (32 bits cover grids of
// up to 4.29 Gvoxel; the thesis's largest is 0.6 Gvoxel), kept in ascending order.
struct SparseVolume {
  VoxelGrid grid;
  std::vector<std::uint32_t> index;
  std::vector<float> intensity;

  std::size_t size() const { return index.size(); }
  DenseVolume to_dense() const {
    DenseVolume dense(grid);
    for (std::size_t n = 0; n < index.size(); ++n) dense.values[index[n]] = intensity[n];
    return dense;
  }
};

}  // namespace tomorig
