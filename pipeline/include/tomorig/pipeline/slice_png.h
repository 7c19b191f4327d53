#pragma once
// A picture of one z-slice of a displacement field, for reports (quicklook::vector_slice_plot):
// each node a cell whose grey level is the in-plane displacement magnitude (colour bar), an
// arrow per valid node with a reference arrow for scale, axes; invalid nodes are black.
#include <filesystem>
#include <vector>

#include "tomorig/core/geometry.h"

namespace tomorig::pipeline {

// `displacement` and `counted` hold nx * ny * nz nodes (x fastest); nodes with counted == 0 are
// drawn black. `origin_mm` and `spacing_mm` place the nodes (the results file's), so the axes are
// in mm; a spacing that is not > 0 gives axes in node numbers. Writes an 8-bit PNG through
// storage::write_png.
void write_slice_png(const std::filesystem::path& file, int nx, int ny, int nz, int k,
                     const std::vector<Vec3d>& displacement, const std::vector<bool>& counted, Vec3d origin_mm = {},
                     Vec3d spacing_mm = {});

}  // namespace tomorig::pipeline
