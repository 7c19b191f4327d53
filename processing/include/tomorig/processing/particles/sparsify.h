#pragma once
// Dense -> sparse: keep the voxels above a floor. The particle and quality code work on
// sparse volumes (a few % of a 42-Mvoxel grid are active), so dense input goes through here.
#include "tomorig/core/volume.h"

namespace tomorig::particles {

// The voxels of `dense` whose value is > `floor` (NaN never is), ascending indices.
// Throws tomorig::Error (bad_input) if the grid has more voxels than 32-bit indices reach
// or the value count does not match the grid. OpenMP over z-slices; the result never
// depends on the thread count (threads = 0: the OpenMP default).
SparseVolume sparsify(const DenseVolume& dense, float floor = 0.0f, int threads = 0);

}  // namespace tomorig::particles
