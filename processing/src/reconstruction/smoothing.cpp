#include "tomorig/processing/reconstruction/smoothing.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::recon {
namespace {

// Normalised 1-D Gaussian taps for offsets -radius..radius; radius 0 means identity.
std::vector<float> kernel(double sigma) {
  if (sigma < 0.25) return {1.0f};
  const int radius = static_cast<int>(std::ceil(3.0 * sigma));
  std::vector<float> taps(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int d = -radius; d <= radius; ++d) sum += std::exp(-0.5 * d * d / (sigma * sigma));
  for (int d = -radius; d <= radius; ++d)
    taps[static_cast<std::size_t>(d + radius)] = static_cast<float>(std::exp(-0.5 * d * d / (sigma * sigma)) / sum);
  return taps;
}

// out[i] = sum_d taps[d] in[i + d * stride], for n samples along one line (zero outside).
void convolve_line(const float* in, float* out, int n, std::ptrdiff_t stride, const std::vector<float>& taps) {
  const int radius = static_cast<int>(taps.size() / 2);
  for (int i = 0; i < n; ++i) {
    float acc = 0.0f;
    const int lo = std::max(-radius, -i), hi = std::min(radius, n - 1 - i);
    for (int d = lo; d <= hi; ++d) acc += taps[static_cast<std::size_t>(d + radius)] * in[(i + d) * stride];
    out[i * stride] = acc;
  }
}

}  // namespace

SparseVolume gaussian_smooth(const SparseVolume& volume, const Vec3d& sigma, int threads) {
  for (const double s : {sigma.x, sigma.y, sigma.z})
    if (!(s >= 0.0) || !std::isfinite(s))
      throw bad_input(fmt::format("smoothing sigma ({}, {}, {}) voxel must be finite and >= 0", sigma.x, sigma.y, sigma.z));
  const VoxelGrid& g = volume.grid;
  if (volume.index.size() != volume.intensity.size() ||
      (!volume.index.empty() && volume.index.back() >= g.voxel_count()))
    throw bad_input("cannot smooth a sparse volume whose indices and intensities disagree or leave its grid");
  const std::vector<float> kx = kernel(sigma.x), ky = kernel(sigma.y), kz = kernel(sigma.z);
  const int rz = static_cast<int>(kz.size() / 2);
  const std::size_t nx = static_cast<std::size_t>(g.nx), ny = static_cast<std::size_t>(g.ny);
  const std::size_t slice = nx * ny;

  // Slice k of the output needs input slices k - rz .. k + rz; slices are smoothed in x and y
  // first (dense, one slice at a time), then combined along z. Memory: (2 rz + 1) + 1 slices
  // per thread, never the whole dense volume.
  std::vector<std::size_t> slice_start(static_cast<std::size_t>(g.nz) + 1);
  for (int k = 0, n = 0; k <= g.nz; ++k) {
    while (static_cast<std::size_t>(n) < volume.size() && volume.index[static_cast<std::size_t>(n)] < slice * static_cast<std::size_t>(k)) ++n;
    slice_start[static_cast<std::size_t>(k)] = static_cast<std::size_t>(n);
  }
  std::vector<SparseVolume> parts(static_cast<std::size_t>(g.nz));
  if (threads <= 0) threads = omp_get_max_threads();
#pragma omp parallel num_threads(threads)
  {
    std::vector<float> planes(slice * static_cast<std::size_t>(2 * rz + 1)), scratch(slice), out(slice);
#pragma omp for schedule(dynamic, 4)
    for (int k = 0; k < g.nz; ++k) {
      bool any = false;
      for (int dz = -rz; dz <= rz; ++dz) {
        float* plane = planes.data() + slice * static_cast<std::size_t>(dz + rz);
        std::fill(plane, plane + slice, 0.0f);
        const int kk = k + dz;
        if (kk < 0 || kk >= g.nz) continue;
        const std::size_t base = slice * static_cast<std::size_t>(kk);
        for (std::size_t n = slice_start[static_cast<std::size_t>(kk)]; n < slice_start[static_cast<std::size_t>(kk) + 1]; ++n) {
          plane[volume.index[n] - base] = volume.intensity[n];
          any = true;
        }
        if (slice_start[static_cast<std::size_t>(kk)] == slice_start[static_cast<std::size_t>(kk) + 1]) continue;
        for (std::size_t j = 0; j < ny; ++j) convolve_line(plane + j * nx, scratch.data() + j * nx, g.nx, 1, kx);
        for (std::size_t i = 0; i < nx; ++i)
          convolve_line(scratch.data() + i, plane + i, g.ny, static_cast<std::ptrdiff_t>(nx), ky);
      }
      if (!any) continue;
      std::fill(out.begin(), out.end(), 0.0f);
      for (int dz = -rz; dz <= rz; ++dz) {
        const float w = kz[static_cast<std::size_t>(dz + rz)];
        const float* plane = planes.data() + slice * static_cast<std::size_t>(rz - dz);  // input slice k - dz
        for (std::size_t p = 0; p < slice; ++p) out[p] += w * plane[p];
      }
      SparseVolume& part = parts[static_cast<std::size_t>(k)];
      const std::size_t base = slice * static_cast<std::size_t>(k);
      for (std::size_t p = 0; p < slice; ++p)
        if (out[p] > 0.0f) {
          part.index.push_back(static_cast<std::uint32_t>(base + p));
          part.intensity.push_back(out[p]);
        }
    }
  }
  SparseVolume result;
  result.grid = g;
  std::size_t total = 0;
  for (const auto& p : parts) total += p.size();
  result.index.reserve(total);
  result.intensity.reserve(total);
  for (const auto& p : parts) {
    result.index.insert(result.index.end(), p.index.begin(), p.index.end());
    result.intensity.insert(result.intensity.end(), p.intensity.begin(), p.intensity.end());
  }
  return result;
}

}  // namespace tomorig::recon
