#pragma once
// XDMF 3 text for a results file: one uniform grid per set (displacement, velocity, status,
// peak, and the ensemble statistics beside them), all node-centred on the interrogation grid.
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::storage {

struct XdmfFieldGrid {
  int nx = 0, ny = 0, nz = 0;
  Vec3d origin, spacing;  // mm
};

// Format version 2: each set is a row of the /sets datasets (`rows` long). `file_name`: the
// HDF5 file's name relative to the .xdmf.
struct XdmfSetRow {
  std::uint64_t set_index = 0;
  std::uint64_t row = 0;
};
std::string xdmf_for_result_rows(const std::string& file_name, const XdmfFieldGrid& grid,
                                 const std::vector<XdmfSetRow>& sets, std::uint64_t rows, bool has_statistics);

}  // namespace tomorig::storage
