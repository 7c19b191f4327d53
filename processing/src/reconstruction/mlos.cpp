#include "mlos.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <numeric>
#include <string>

#include <fmt/core.h>

#include "system_memory.h"
#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
namespace {

// A thresholded copy of an image with a one-pixel border of zeros, so that bilinear sampling
// anywhere inside the image span [-0.5, W - 0.5] needs no bounds checks.
struct SampledImage {
  int width = 0, height = 0, stride = 0;
  std::vector<float> pixels;
  double nonzero_fraction = 0.0;

  SampledImage(const CameraImage& image, double threshold) : width(image.width), height(image.height) {
    stride = width + 2;
    pixels.assign(static_cast<std::size_t>(stride) * (height + 2), 0.0f);
    const float cut = static_cast<float>(threshold) * image.max;
    std::size_t nonzero = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const float v = image.at(x, y);
        if (v > 0 && v >= cut) {
          pixels[static_cast<std::size_t>(y + 1) * stride + x + 1] = v;
          ++nonzero;
        }
      }
    nonzero_fraction = static_cast<double>(nonzero) / (static_cast<double>(width) * height);
  }

  // reach[y * stride + x] != 0 iff one of the four pixels a bilinear sample with
  // x = floor(u + 1), y = floor(v + 1) reads is non-empty: one byte decides most voxels.
  std::vector<std::uint8_t> reach;
  double reach_fraction = 0.0;

  void build_reach() {
    reach.assign(pixels.size(), 0);
    std::size_t count = 0;
    for (int y = 0; y <= height; ++y)
      for (int x = 0; x <= width; ++x) {
        const float* p = pixels.data() + static_cast<std::size_t>(y) * stride + x;
        const bool any = p[0] > 0 || p[1] > 0 || p[stride] > 0 || p[stride + 1] > 0;
        reach[static_cast<std::size_t>(y) * stride + x] = any;
        count += any;
      }
    reach_fraction = static_cast<double>(count) / (static_cast<double>(width + 1) * (height + 1));
  }

  // Whether (u, v) lies inside the image span and next to a non-empty pixel.
  bool reaches(float u, float v) const {
    const bool in = u >= -0.5f && u <= width - 0.5f && v >= -0.5f && v <= height - 0.5f;
    const int x = in ? static_cast<int>(u + 1.0f) : 0, y = in ? static_cast<int>(v + 1.0f) : 0;
    return in && reach[static_cast<std::size_t>(y) * stride + x] != 0;
  }

  // Bilinear interpolation at (u, v) known to be inside the image span.
  float sample_inside(float u, float v) const {
    const int x = static_cast<int>(u + 1.0f), y = static_cast<int>(v + 1.0f);
    const float ax = u + 1.0f - static_cast<float>(x), ay = v + 1.0f - static_cast<float>(y);
    const float* p = pixels.data() + static_cast<std::size_t>(y) * stride + x;
    const float top = p[0] + ax * (p[1] - p[0]);
    const float bottom = p[stride] + ax * (p[stride + 1] - p[stride]);
    return top + ay * (bottom - top);
  }
};

struct SliceResult {
  std::vector<std::uint32_t> index;
  std::vector<float> value;
};

}  // namespace

ActiveSet run_mlos(const PreparedInput& in, const GridProjector& projector, const MlosSettings& settings) {
  const VoxelGrid& g = in.grid;
  const std::size_t cams = in.camera_count();
  std::vector<SampledImage> images;
  for (const CameraImage& image : in.images) {
    images.emplace_back(image, settings.threshold);
    images.back().build_reach();
  }
  // The most selective camera first: most voxels then stop after one lookup.
  std::vector<std::size_t> order(cams);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return images[a].reach_fraction < images[b].reach_fraction;
  });

  const double limit_mb = settings.memory_limit_mb > 0 ? settings.memory_limit_mb : usable_memory_mb();
  const double budget_voxels =
      limit_mb > 0 && settings.bytes_per_voxel > 0
          ? (limit_mb * 1024.0 * 1024.0 - settings.fixed_bytes) / settings.bytes_per_voxel
          : 1e300;
  std::atomic<std::size_t> active{0};
  std::atomic<bool> over_budget{false};

  std::vector<SliceResult> slices(static_cast<std::size_t>(g.nz));
#pragma omp parallel num_threads(in.threads)
  {
    std::vector<float> u(static_cast<std::size_t>(g.nx) * cams), v(static_cast<std::size_t>(g.nx) * cams);
    std::vector<float> product(static_cast<std::size_t>(g.nx));
    std::vector<int> alive(static_cast<std::size_t>(g.nx));
#pragma omp for schedule(dynamic, 1)
    for (int k = 0; k < g.nz; ++k) {
      if (over_budget.load(std::memory_order_relaxed)) continue;
      SliceResult& out = slices[static_cast<std::size_t>(k)];
      for (int j = 0; j < g.ny; ++j) {
        // First camera: the whole row's positions (a linear fill), one byte of the reach mask
        // per voxel, and the bilinear sample only where it can be non-zero. Later cameras:
        // positions and samples of the surviving voxels only.
        int count = 0;
        {
          const std::size_t c = order[0];
          float* uc = u.data() + c * g.nx;
          float* vc = v.data() + c * g.nx;
          projector.row(c, j, k, uc, vc);
          const SampledImage& image = images[c];
          for (int i = 0; i < g.nx; ++i) {
            alive[count] = i;
            count += image.reaches(uc[i], vc[i]);
          }
          int kept = 0;
          for (int n = 0; n < count; ++n) {
            const int i = alive[n];
            const float s = image.sample_inside(uc[i], vc[i]);
            product[i] = s;
            alive[kept] = i;
            kept += s > 0.0f;
          }
          count = kept;
        }
        for (std::size_t o = 1; o < cams && count > 0; ++o) {
          const std::size_t c = order[o];
          float* uc = u.data() + c * g.nx;
          float* vc = v.data() + c * g.nx;
          projector.row_at(c, j, k, alive.data(), count, uc, vc);
          const SampledImage& image = images[c];
          int kept = 0;
          for (int n = 0; n < count; ++n) {
            const int i = alive[n];
            const float s = image.reaches(uc[i], vc[i]) ? image.sample_inside(uc[i], vc[i]) : 0.0f;
            product[i] *= s;
            alive[kept] = i;
            kept += s > 0.0f;
          }
          count = kept;
        }
        for (int n = 0; n < count; ++n) {
          const int i = alive[n];
          out.index.push_back(static_cast<std::uint32_t>(g.linear(i, j, k)));
          out.value.push_back(product[i]);
        }
      }
      const std::size_t total = active.fetch_add(out.index.size()) + out.index.size();
      if (static_cast<double>(total) > budget_voxels) over_budget.store(true);
    }
  }
  if (over_budget.load()) {
    const std::string what = fmt::format("the MLOS support (at least {} active voxels)", active.load());
    const double bytes = settings.fixed_bytes + settings.bytes_per_voxel * static_cast<double>(active.load());
    require_memory(bytes, limit_mb, what);
    throw bad_input(fmt::format("reconstruction: {} needs more than the {:.0f} MB available", what, limit_mb));
  }

  // Slices concatenated in z order; each slice copies into its own range, in parallel.
  ActiveSet set;
  std::vector<std::size_t> first(slices.size() + 1, 0);
  for (std::size_t k = 0; k < slices.size(); ++k) first[k + 1] = first[k] + slices[k].index.size();
  const std::size_t total = first.back();
  set.index.resize(total);
  set.value.resize(total);
#pragma omp parallel for num_threads(in.threads) schedule(dynamic, 4)
  for (int k = 0; k < g.nz; ++k) {
    SliceResult& s = slices[static_cast<std::size_t>(k)];
    const std::size_t at = first[static_cast<std::size_t>(k)];
    std::copy(s.index.begin(), s.index.end(), set.index.begin() + at);
    std::copy(s.value.begin(), s.value.end(), set.value.begin() + at);
    s = {};
  }
  return set;
}

}  // namespace tomorig::recon::detail
