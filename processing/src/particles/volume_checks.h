#pragma once
// Input checks shared by the quality metrics: a grid must be non-empty, indexable with 32-bit
// linear indices (SparseVolume), and a sparse volume must match its grid.
#include <cstdint>
#include <string>

#include "tomorig/core/volume.h"

namespace tomorig::particles::detail {

// Throws tomorig::Error (bad_input) naming `what` and the field that is wrong.
void check_grid(const VoxelGrid& grid, const std::string& what);
// Also checks that index and intensity have equal sizes and indices ascend inside the grid.
void check_sparse(const SparseVolume& volume, const std::string& what);
// Throws bad_input if the two grids differ (dimensions, origin or voxel size).
void check_same_grid(const VoxelGrid& a, const VoxelGrid& b, const std::string& what_a, const std::string& what_b);

}  // namespace tomorig::particles::detail
