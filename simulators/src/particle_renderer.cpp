#include "tomorig/simulators/particle_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <fmt/core.h>

#include "parallel.h"
#include "tomorig/core/error.h"

namespace tomorig::sim {
namespace {

// Rows per unit of parallel work. Fixed (not derived from the thread count) so the split,
// and with it the summation order, is the same on any machine.
constexpr int kBandRows = 16;

// The clipped pixel window of one particle; nx = 0: nothing falls on the image.
struct Footprint {
  int x0 = 0, y0 = 0;
  int nx = 0, ny = 0;
};

// Pixel-integrated 1-D Gaussian over pixels first..first+count-1 (pixel i spans
// [i - 1/2, i + 1/2]), times `scale`: erf differences, so each weight is the exact integral.
void pixel_weights(double centre, int first, int count, double inv_sqrt2_sigma, double scale, double* out) {
  double previous = std::erf((first - 0.5 - centre) * inv_sqrt2_sigma);
  for (int c = 0; c < count; ++c) {
    const double next = std::erf((first + c + 0.5 - centre) * inv_sqrt2_sigma);
    out[c] = 0.5 * (next - previous) * scale;
    previous = next;
  }
}

// Pixels [first, last] of an axis of `size` pixels that a window [centre - r, centre + r]
// overlaps, clipped to the image; false if none.
bool window(double centre, double r, int size, int& first, int& count) {
  if (!(centre + r > -0.5) || !(centre - r < size - 0.5)) return false;  // also rejects NaN
  const int lo = std::max(0, static_cast<int>(std::floor(centre - r + 0.5)));
  const int hi = std::min(size - 1, static_cast<int>(std::floor(centre + r + 0.5)));
  first = lo;
  count = hi - lo + 1;
  return count > 0;
}

// Work buffers, one set per calling thread, kept between calls: rendering a stream of images
// allocates (and page-faults) nothing after the first. The OpenMP team of a call shares its
// caller's buffers, each thread writing disjoint slots.
struct Scratch {
  std::vector<ParticleImage> images;
  std::vector<Footprint> footprints;
  std::vector<double> gx, gy;
  std::vector<std::uint32_t> band_start, members, fill;
};

Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

}  // namespace

void ParticleImageOptions::validate() const {
  if (!(sigma_px > 0) || !std::isfinite(sigma_px))
    throw bad_input(fmt::format("particle images: sigma_px = {} must be > 0", sigma_px));
  if (!std::isfinite(peak_counts) || peak_counts < 0)
    throw bad_input(fmt::format("particle images: peak_counts = {} must be >= 0", peak_counts));
  if (!(window_sigmas >= 3 && window_sigmas <= 20))
    throw bad_input(fmt::format("particle images: window_sigmas = {} must be in [3, 20]", window_sigmas));
  if (threads < 0) throw bad_input(fmt::format("particle images: threads = {} must be >= 0", threads));
}

void render_particle_images(std::span<const ParticleImage> particles, const ParticleImageOptions& options,
                            Image& signal) {
  options.validate();
  if (signal.empty() || signal.type() != SampleType::f32)
    throw runtime_error("render_particle_images: the signal image must be an allocated f32 image");
  if (particles.size() >= std::numeric_limits<std::uint32_t>::max())
    throw bad_input(fmt::format("particle images: {} particles is more than one image can take", particles.size()));

  const int width = signal.width(), height = signal.height();
  const double r = options.window_sigmas * options.sigma_px;
  const int max_w = static_cast<int>(std::ceil(2 * r)) + 2;  // most pixels a window overlaps
  const double inv_sqrt2_sigma = 1.0 / (std::numbers::sqrt2 * options.sigma_px);
  const double area = 2 * std::numbers::pi * options.sigma_px * options.sigma_px;  // integral / peak
  const int threads = detail::thread_count(options.threads);
  const std::size_t n = particles.size();

  // 1. Per particle: window and separable weights (gx carries the amplitude). Each particle
  //    writes only its own slots.
  Scratch& work = scratch();
  std::vector<Footprint>& footprints = work.footprints;
  std::vector<double>& gx = work.gx;
  std::vector<double>& gy = work.gy;
  footprints.resize(n);
  gx.resize(n * max_w);  // only grows: no reallocation or zeroing after the first images
  gy.resize(n * max_w);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    const ParticleImage& p = particles[i];
    Footprint f;
    if (p.peak != 0 && window(p.centre.x, r, width, f.x0, f.nx) && window(p.centre.y, r, height, f.y0, f.ny)) {
      pixel_weights(p.centre.x, f.x0, f.nx, inv_sqrt2_sigma, p.peak * area, &gx[i * max_w]);
      pixel_weights(p.centre.y, f.y0, f.ny, inv_sqrt2_sigma, 1.0, &gy[i * max_w]);
    } else {
      f.nx = f.ny = 0;
    }
    footprints[i] = f;
  }

  // 2. Bucket particles by the row bands they touch, keeping the particle order in each band.
  const int bands = (height + kBandRows - 1) / kBandRows;
  std::vector<std::uint32_t>& band_start = work.band_start;
  band_start.assign(bands + 1, 0);
  for (const Footprint& f : footprints)
    if (f.nx > 0)
      for (int b = f.y0 / kBandRows; b <= (f.y0 + f.ny - 1) / kBandRows; ++b) ++band_start[b + 1];
  for (int b = 0; b < bands; ++b) band_start[b + 1] += band_start[b];
  std::vector<std::uint32_t>& members = work.members;
  std::vector<std::uint32_t>& fill = work.fill;
  members.resize(band_start[bands]);
  fill.assign(band_start.begin(), band_start.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    const Footprint& f = footprints[i];
    if (f.nx > 0)
      for (int b = f.y0 / kBandRows; b <= (f.y0 + f.ny - 1) / kBandRows; ++b)
        members[fill[b]++] = static_cast<std::uint32_t>(i);
  }

  // 3. Each band adds its particles' rows: bands own disjoint rows, so no two threads touch
  //    a pixel, and each pixel sums in particle order.
  std::byte* const base = signal.data();
  const std::size_t stride = signal.stride_bytes();
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
  for (int b = 0; b < bands; ++b) {
    const int row_lo = b * kBandRows, row_hi = std::min(height, row_lo + kBandRows);
    for (std::uint32_t m = band_start[b]; m < band_start[b + 1]; ++m) {
      const std::uint32_t i = members[m];
      const Footprint& f = footprints[i];
      const double* wx = &gx[static_cast<std::size_t>(i) * max_w];
      const double* wy = &gy[static_cast<std::size_t>(i) * max_w];
      const int y_lo = std::max(f.y0, row_lo), y_hi = std::min(f.y0 + f.ny, row_hi);
      for (int y = y_lo; y < y_hi; ++y) {
        float* row = reinterpret_cast<float*>(base + static_cast<std::size_t>(y) * stride) + f.x0;
        const double w = wy[y - f.y0];
        for (int c = 0; c < f.nx; ++c) row[c] += static_cast<float>(w * wx[c]);
      }
    }
  }
}

void render_particles(const calibration::CameraModel& camera, std::span<const Vec3d> particles,
                      const LightSheet& sheet, const ParticleImageOptions& options, Image& signal) {
  options.validate();
  std::vector<ParticleImage>& images = scratch().images;
  images.resize(particles.size());
  const int threads = detail::thread_count(options.threads);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (std::size_t i = 0; i < particles.size(); ++i)
    images[i] = {camera.project(particles[i]), options.peak_counts * sheet.intensity(particles[i].z)};
  render_particle_images(images, options, signal);
}

}  // namespace tomorig::sim
