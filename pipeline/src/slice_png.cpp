#include "tomorig/pipeline/slice_png.h"

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/vector_slice_plot.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::pipeline {

void write_slice_png(const std::filesystem::path& file, int nx, int ny, int nz, int k,
                     const std::vector<Vec3d>& displacement, const std::vector<bool>& counted, Vec3d origin_mm,
                     Vec3d spacing_mm) {
  if (k < 0 || k >= nz) throw bad_input("slice index out of range for the PNG");
  quicklook::VectorSlice slice;
  slice.nx = nx;
  slice.ny = ny;
  const std::size_t first = static_cast<std::size_t>(nx) * ny * k;
  slice.displacement.assign(displacement.begin() + first, displacement.begin() + first + slice.nx * ny);
  slice.valid.assign(counted.begin() + first, counted.begin() + first + slice.nx * ny);
  if (spacing_mm.x > 0 && spacing_mm.y > 0) {
    // One spacing for both axes: the plot's cells are square (tomorig's grids space x and y alike).
    slice.x0 = origin_mm.x;
    slice.y0 = origin_mm.y;
    slice.spacing = spacing_mm.x;
    slice.axis_unit = "mm";
    slice.title = fmt::format("mean displacement, z-slice {} of {} (z = {:.4g} mm)", k, nz, origin_mm.z + k * spacing_mm.z);
  } else {
    slice.title = fmt::format("mean displacement, z-slice {} of {} (nodes)", k, nz);
  }
  storage::write_png(file, quicklook::vector_slice_plot(slice));
}

}  // namespace tomorig::pipeline
