#pragma once
// The sparse support of a reconstruction: active voxels in ascending linear index, an initial
// intensity each, as produced by MLOS. Image positions are not kept: the sparse system
// recomputes them from the GridProjector, which costs less than storing 8 bytes per voxel and
// camera, copying them once more when the slices are joined, and reading them back.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tomorig::recon::detail {

struct ActiveSet {
  std::vector<std::uint32_t> index;
  std::vector<float> value;

  std::size_t size() const { return index.size(); }
};

}  // namespace tomorig::recon::detail
