#include "tomorig/processing/quicklook/display.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

template <typename T>
void gather(const Image& image, std::vector<float>& out) {
  for (int y = 0; y < image.height(); ++y) {
    const T* row = image.row<T>(y);
    for (int x = 0; x < image.width(); ++x) {
      const float v = static_cast<float>(row[x]);
      out.push_back(std::isfinite(v) ? v : 0.0f);
    }
  }
}

std::vector<float> samples_of(const Image& image) {
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(image.width()) * static_cast<std::size_t>(image.height()));
  switch (image.type()) {
    case SampleType::u8: gather<std::uint8_t>(image, out); break;
    case SampleType::u16: gather<std::uint16_t>(image, out); break;
    case SampleType::f32: gather<float>(image, out); break;
  }
  return out;
}

float percentile(std::vector<float>& sorted_copy, double p) {
  const std::size_t n = sorted_copy.size();
  const auto k = static_cast<std::size_t>(std::llround(p / 100.0 * static_cast<double>(n - 1)));
  std::nth_element(sorted_copy.begin(), sorted_copy.begin() + static_cast<std::ptrdiff_t>(k), sorted_copy.end());
  return sorted_copy[k];
}

}  // namespace

void StretchOptions::validate() const {
  if (!(low_percentile >= 0.0 && low_percentile < high_percentile && high_percentile <= 100.0))
    throw bad_input(fmt::format("quick-look stretch percentiles {} and {} are not valid: need 0 <= low < high <= 100",
                                low_percentile, high_percentile));
}

Image stretch_to_8bit(const Image& image, const StretchOptions& options) {
  options.validate();
  if (image.empty()) throw bad_input("cannot make a quick-look of an empty image");
  const std::vector<float> values = samples_of(image);
  std::vector<float> scratch = values;
  const float low = percentile(scratch, options.low_percentile);
  const float high = percentile(scratch, options.high_percentile);
  Image out = Image::allocate(image.width(), image.height(), SampleType::u8);
  if (!(high > low)) return out;  // flat image: black
  const float scale = 255.0f / (high - low);
  std::size_t n = 0;
  for (int y = 0; y < image.height(); ++y) {
    std::uint8_t* row = out.row<std::uint8_t>(y);
    for (int x = 0; x < image.width(); ++x, ++n)
      row[x] = static_cast<std::uint8_t>(std::clamp((values[n] - low) * scale, 0.0f, 255.0f) + 0.5f);
  }
  return out;
}

namespace {

// Projection image size and the pixel a voxel lands on.
struct ProjectionShape {
  int width, height;
};

ProjectionShape shape_of(const VoxelGrid& g, Axis axis) {
  switch (axis) {
    case Axis::z: return {g.nx, g.ny};
    case Axis::y: return {g.nx, g.nz};
    case Axis::x: return {g.ny, g.nz};
  }
  return {0, 0};
}

void check_grid(const VoxelGrid& g) {
  if (g.nx <= 0 || g.ny <= 0 || g.nz <= 0)
    throw bad_input(fmt::format("cannot project a {} x {} x {} volume", g.nx, g.ny, g.nz));
}

template <typename ForEachVoxel>
Image project(const VoxelGrid& g, Axis axis, ForEachVoxel&& for_each_voxel) {
  check_grid(g);
  const ProjectionShape s = shape_of(g, axis);
  Image out = Image::allocate(s.width, s.height, SampleType::f32);
  for_each_voxel([&](std::size_t linear, float value) {
    const std::size_t nx = static_cast<std::size_t>(g.nx), ny = static_cast<std::size_t>(g.ny);
    const int i = static_cast<int>(linear % nx);
    const int j = static_cast<int>((linear / nx) % ny);
    const int k = static_cast<int>(linear / (nx * ny));
    const int u = axis == Axis::x ? j : i;
    const int v = axis == Axis::z ? j : k;
    float& pixel = out.at<float>(u, v);
    pixel = std::max(pixel, value);
  });
  return out;
}

}  // namespace

Image max_projection(const SparseVolume& volume, Axis axis) {
  if (volume.index.size() != volume.intensity.size())
    throw bad_input("cannot project a sparse volume whose index and intensity lists differ in length");
  return project(volume.grid, axis, [&](auto&& visit) {
    for (std::size_t n = 0; n < volume.size(); ++n) {
      if (volume.index[n] >= volume.grid.voxel_count())
        throw bad_input("cannot project a sparse volume with an index outside its grid");
      visit(volume.index[n], volume.intensity[n]);
    }
  });
}

Image max_projection(const DenseVolume& volume, Axis axis) {
  if (volume.values.size() != volume.grid.voxel_count())
    throw bad_input("cannot project a dense volume whose size does not match its grid");
  return project(volume.grid, axis, [&](auto&& visit) {
    for (std::size_t n = 0; n < volume.values.size(); ++n) visit(n, volume.values[n]);
  });
}

}  // namespace tomorig::quicklook

namespace tomorig::quicklook {
namespace {

template <typename T>
void block_max(const Image& in, int block, Image& out) {
  if constexpr (std::is_integral_v<T>) {
    // Camera frames: the block's rows folded into one row by an element-wise maximum (a loop
    // the compiler vectorises, once over every pixel), then each block's run of that row.
    std::vector<T> folded(static_cast<std::size_t>(in.width()));
    for (int y = 0; y < out.height(); ++y) {
      const int first = y * block, last = std::min(in.height(), first + block);
      std::copy_n(in.row<T>(first), in.width(), folded.begin());
      for (int yy = first + 1; yy < last; ++yy) {
        const T* r = in.row<T>(yy);
        T* f = folded.data();
#pragma omp simd
        for (int x = 0; x < in.width(); ++x) f[x] = f[x] > r[x] ? f[x] : r[x];
      }
      float* o = out.row<float>(y);
      for (int x = 0; x < out.width(); ++x) {
        const int x0 = x * block, x1 = std::min(in.width(), x0 + block);
        o[x] = static_cast<float>(*std::max_element(folded.begin() + x0, folded.begin() + x1));
      }
    }
  } else {
    for (int y = 0; y < out.height(); ++y) {
      float* o = out.row<float>(y);
      std::fill(o, o + out.width(), -std::numeric_limits<float>::infinity());
      for (int dy = 0; dy < block && y * block + dy < in.height(); ++dy) {
        const T* r = in.row<T>(y * block + dy);
        for (int x = 0; x < out.width(); ++x)
          for (int dx = 0; dx < block && x * block + dx < in.width(); ++dx)
            o[x] = std::max(o[x], static_cast<float>(r[x * block + dx]));
      }
    }
  }
}

}  // namespace

Image thumbnail(const Image& image, int max_side, const StretchOptions& options) {
  if (image.empty()) throw bad_input("cannot make a thumbnail of an empty image");
  if (max_side < 1) throw bad_input(fmt::format("thumbnail size {} is not valid: it must be >= 1 px", max_side));
  const int longer = std::max(image.width(), image.height());
  const int block = (longer + max_side - 1) / max_side;
  if (block <= 1) return stretch_to_8bit(image, options);
  Image reduced = Image::allocate((image.width() + block - 1) / block, (image.height() + block - 1) / block,
                                  SampleType::f32);
  switch (image.type()) {
    case SampleType::u8: block_max<std::uint8_t>(image, block, reduced); break;
    case SampleType::u16: block_max<std::uint16_t>(image, block, reduced); break;
    case SampleType::f32: block_max<float>(image, block, reduced); break;
  }
  return stretch_to_8bit(reduced, options);
}

Image histogram_image(std::span<const std::uint32_t> counts, int width, int height) {
  if (width < 1 || height < 1)
    throw bad_input(fmt::format("histogram picture of {} x {} px is not valid", width, height));
  Image out = Image::allocate(width, height, SampleType::u8);
  if (counts.empty()) return out;
  double top = 0;
  for (const std::uint32_t c : counts) top = std::max(top, std::log1p(static_cast<double>(c)));
  if (top <= 0) return out;
  for (int x = 0; x < width; ++x) {
    // The bins this column covers; the column shows the fullest.
    const std::size_t first = static_cast<std::size_t>(x) * counts.size() / static_cast<std::size_t>(width);
    const std::size_t last =
        std::max(first + 1, static_cast<std::size_t>(x + 1) * counts.size() / static_cast<std::size_t>(width));
    std::uint32_t c = 0;
    for (std::size_t b = first; b < last && b < counts.size(); ++b) c = std::max(c, counts[b]);
    if (x == width - 1) c = counts.back();  // the saturated bin always has its own column
    if (c == 0) continue;
    const int bar = std::max(1, static_cast<int>(std::lround(std::log1p(static_cast<double>(c)) / top * height)));
    for (int y = height - bar; y < height; ++y) out.at<std::uint8_t>(x, y) = 255;
  }
  return out;
}

}  // namespace tomorig::quicklook
