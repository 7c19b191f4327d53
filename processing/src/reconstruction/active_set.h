#pragma once
// The sparse support of a reconstruction: active voxels in ascending linear index, an initial
// intensity each, and (optionally) their image position in every camera, as produced by MLOS.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace tomorig::recon::detail {

struct ActiveSet {
  std::vector<std::uint32_t> index;
  std::vector<float> value;
  std::vector<std::vector<float>> u, v;  // [camera][voxel]; empty when positions were not kept

  std::size_t size() const { return index.size(); }
};

}  // namespace tomorig::recon::detail
