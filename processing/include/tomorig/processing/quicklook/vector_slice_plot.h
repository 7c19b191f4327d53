#pragma once
// A picture of one slice of a displacement field for reports (issue 23: "vector slices with
// axes, scale and colour bar"): one cell per node, its grey level the in-plane displacement
// magnitude (colour bar on the right, white = the largest), an arrow per valid node (a reference
// arrow below the plot gives the scale), axes with node numbers or millimetres, and nodes
// without a valid vector in black. An 8-bit grey image, for storage::write_png.
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"

namespace tomorig::quicklook {

struct VectorSlice {
  int nx = 0, ny = 0;                // nodes of the slice
  std::vector<Vec3d> displacement;   // nx * ny, x fastest, voxel
  std::vector<bool> valid;           // nx * ny
  double x0 = 0.0, y0 = 0.0;         // axis position of node (0, 0)
  double spacing = 1.0;              // axis distance between nodes
  std::string axis_unit = "node";    // "node" or "mm"
  std::string title;
};

// Pixel layout, for tests: the plot area and the colour bar.
struct VectorSliceLayout {
  int cell = 0;
  int plot_left = 0, plot_top = 0;       // top-left of node (0, 0)'s cell
  int bar_left = 0, bar_top = 0, bar_width = 0, bar_height = 0;
};

// Throws bad_input for an empty slice or sizes that disagree.
Image vector_slice_plot(const VectorSlice& slice, VectorSliceLayout* layout = nullptr);

}  // namespace tomorig::quicklook
