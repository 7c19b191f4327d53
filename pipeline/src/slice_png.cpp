#include "tomorig/pipeline/slice_png.h"

#include <algorithm>
#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/core/image.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::pipeline {

void write_slice_png(const std::filesystem::path& file, int nx, int ny, int nz, int k,
                     const std::vector<Vec3d>& displacement, const std::vector<bool>& counted, int cell) {
  if (k < 0 || k >= nz) throw bad_input("slice index out of range for the PNG");
  Image image = Image::allocate(nx * cell, ny * cell, SampleType::u8);
  const auto node = [&](int i, int j) { return static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k); };
  double largest = 0.0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      if (counted[node(i, j)]) largest = std::max(largest, std::hypot(displacement[node(i, j)].x, displacement[node(i, j)].y));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t n = node(i, j);
      const Vec3d& d = displacement[n];
      const double magnitude = std::hypot(d.x, d.y);
      const auto grey = static_cast<std::uint8_t>(counted[n] && largest > 0 ? 40 + 215 * magnitude / largest : 0);
      for (int y = 0; y < cell; ++y) {
        auto* row = image.row<std::uint8_t>(j * cell + y);
        std::fill(row + i * cell, row + (i + 1) * cell, grey);
      }
      if (!counted[n] || largest <= 0) continue;
      // Direction: a line from the cell centre, half a cell long at the largest magnitude.
      const double length = 0.5 * cell * magnitude / largest;
      const double ux = magnitude > 0 ? d.x / magnitude : 0.0, uy = magnitude > 0 ? d.y / magnitude : 0.0;
      for (double s = 0; s <= length; s += 0.5) {
        const int x = i * cell + cell / 2 + static_cast<int>(std::lround(s * ux));
        const int y = j * cell + cell / 2 + static_cast<int>(std::lround(s * uy));
        if (x >= 0 && y >= 0 && x < nx * cell && y < ny * cell) image.row<std::uint8_t>(y)[x] = 0;
      }
    }
  storage::write_png(file, image);
}

}  // namespace tomorig::pipeline
