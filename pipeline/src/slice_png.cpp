#include "tomorig/pipeline/slice_png.h"

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/vector_slice_plot.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::pipeline {

void write_slice_png(const std::filesystem::path& file, int nx, int ny, int nz, int k,
                     const std::vector<Vec3d>& displacement, const std::vector<bool>& counted) {
  if (k < 0 || k >= nz) throw bad_input("slice index out of range for the PNG");
  quicklook::VectorSlice slice;
  slice.nx = nx;
  slice.ny = ny;
  const std::size_t first = static_cast<std::size_t>(nx) * ny * k;
  slice.displacement.assign(displacement.begin() + first, displacement.begin() + first + slice.nx * ny);
  slice.valid.assign(counted.begin() + first, counted.begin() + first + slice.nx * ny);
  slice.title = fmt::format("mean displacement, z-slice {} of {} (nodes)", k, nz);
  storage::write_png(file, quicklook::vector_slice_plot(slice));
}

}  // namespace tomorig::pipeline
