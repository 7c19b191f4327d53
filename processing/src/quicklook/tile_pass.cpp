#include "tile_pass.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "histogram_stats.h"

namespace tomorig::quicklook::detail {
namespace {

// Sum over x in [x0, x1) of a[x] * b[x + shift], and of b[x + shift]. Float partial sums over
// one tile row: at most a few hundred terms.
void row_products(const float* a, const float* b, int x0, int x1, int shift, float& products, float& sum_b) {
  float p = 0, s = 0;
#pragma omp simd reduction(+ : p, s)
  for (int x = x0; x < x1; ++x) {
    p += a[x] * b[x + shift];
    s += b[x + shift];
  }
  products = p;
  sum_b = s;
}

// The tile's background level and noise from its own histogram (every other pixel of every other
// row: 1024 of a 64 px tile): a window of kTileBins bins placed by the sampled 5th percentile,
// the bins (a power of two counts wide) narrow enough that the sampled 5th to 50th percentiles
// span 16 to 32 of them; half-sample mode and lower-half noise as for
// the whole frame (histogram_stats.h).
template <typename T>
void tile_background(const Image& image, int x0, int x1, int y0, int y1, std::size_t samples, TileSums& t,
                     TileScratch& scratch) {
  std::vector<std::uint16_t>& sample = scratch.sample;
  const auto end = sample.begin() + static_cast<std::ptrdiff_t>(samples);
  const auto k5 = static_cast<std::ptrdiff_t>(0.05 * static_cast<double>(samples - 1));
  const auto k50 = static_cast<std::ptrdiff_t>(0.50 * static_cast<double>(samples - 1));
  std::nth_element(sample.begin(), sample.begin() + k5, end);
  const int p5 = sample[static_cast<std::size_t>(k5)];
  std::nth_element(sample.begin() + k5, sample.begin() + k50, end);
  const int p50 = sample[static_cast<std::size_t>(k50)];
  // Bins of a power-of-two width: a shift, not a division, per pixel.
  int shift = 0;
  while ((32 << shift) < p50 - p5) ++shift;
  const int width = 1 << shift;
  const int origin = p5 - kTileBinsBelow * width;

  std::uint32_t* h = scratch.histogram.data();
  std::fill(h, h + kTileBins, 0u);
  for (int y = y0; y < y1; y += 2) {
    const T* r = image.row<T>(y);
    for (int x = x0; x < x1; x += 2) {
      const int d = static_cast<int>(r[x]) - origin;
      ++h[d < 0 ? 0 : std::min(kTileBins - 1, d >> shift)];
    }
  }
  const std::span<const std::uint32_t> bins(h, kTileBins);
  const double rough = half_sample_mode(bins);
  const double mode = refine_mode(bins, rough, lower_half_sigma(bins, rough));
  // Bin b holds values origin + b * width .. origin + (b + 1) * width - 1.
  t.background = origin + mode * width + 0.5 * (width - 1);
  t.noise = lower_half_sigma(bins, mode) * width;
}

template <typename T>
void accumulate_tile(const Image& image, const TileGrid& g, int i, int j, int full_scale, std::uint32_t* histogram,
                     TileSums& t, TileScratch& scratch) {
  const int x0 = g.x0(i), x1 = g.x1(i), y0 = g.y0(j), y1 = g.y1(j);
  const int w = x1 - x0;
  t = TileSums{};
  const float offset = static_cast<float>(image.row<T>(y0)[x0]);
  t.offset = offset;

  // The tile and a 1 px border (for Sobel) as floats minus the offset, converted once for all
  // the sums below. Integer counts up to 65535 are exact in float.
  const int bx0 = std::max(x0 - 1, 0), bx1 = std::min(x1 + 1, g.width);
  const int by0 = std::max(y0 - 1, 0), by1 = std::min(y1 + 1, g.height);
  const int stride = bx1 - bx0;
  float* buffer = scratch.tile.data();
  for (int y = by0; y < by1; ++y) {
    const T* src = image.row<T>(y);
    float* dst = buffer + static_cast<std::ptrdiff_t>(y - by0) * stride - bx0;
#pragma omp simd
    for (int x = bx0; x < bx1; ++x) dst[x] = static_cast<float>(src[x]) - offset;
  }
  // Row y of the buffer, indexed by image column.
  const auto row = [&](int y) { return buffer + static_cast<std::ptrdiff_t>(y - by0) * stride - bx0; };
  const float saturation = static_cast<float>(full_scale) - offset;
  // Sobel needs the 3 x 3 neighbourhood inside the image (it may reach into other tiles).
  const int sx0 = std::max(x0, 1), sx1 = std::min(x1, g.width - 1);

  std::vector<std::uint16_t>& sample = scratch.sample;
  std::size_t samples = 0;
  std::uint32_t* odd = histogram + kHistogramStride;
  for (int y = y0; y < y1; ++y) {
    const float* r0 = row(y);

    float s = 0, ss = 0;
    int saturated = 0;
#pragma omp simd reduction(+ : s, ss, saturated)
    for (int x = x0; x < x1; ++x) {
      const float d = r0[x];
      s += d;
      ss += d * d;
      saturated += d >= saturation ? 1 : 0;
    }
    t.n += w;
    t.sum += s;
    t.sumsq += ss;
    t.saturated += saturated;

    // Two histograms for even and odd columns: neighbouring pixels often share a value, and
    // one counter would make every increment wait for the previous one.
    const T* raw = image.row<T>(y);
    int x = x0;
    for (; x + 1 < x1; x += 2) {
      ++histogram[raw[x]];
      ++odd[raw[x + 1]];
    }
    if (x < x1) ++histogram[raw[x]];

    // Lags along x: pairs (x, x + 1) and (x, x + 2) inside the tile. The sums of either member
    // are the row sum without the end pixels.
    float products = 0, unused = 0;
    if (w > 1) {
      row_products(r0, r0, x0, x1 - 1, 1, products, unused);
      t.pairs[lag_x1] += w - 1;
      t.sum_xy[lag_x1] += products;
      t.sum_x[lag_x1] += s - r0[x1 - 1];
      t.sum_y[lag_x1] += s - r0[x0];
    }
    if (w > 2) {
      row_products(r0, r0, x0, x1 - 2, 2, products, unused);
      t.pairs[lag_x2] += w - 2;
      t.sum_xy[lag_x2] += products;
      t.sum_x[lag_x2] += s - r0[x1 - 1] - r0[x1 - 2];
      t.sum_y[lag_x2] += s - r0[x0] - r0[x0 + 1];
    }
    // Lags along y: rows y + 1 and y + 2 of the same tile.
    for (int step = 1; step <= 2; ++step) {
      if (y + step >= y1) break;
      float sum_next = 0;
      row_products(r0, row(y + step), x0, x1, 0, products, sum_next);
      const int lag = step == 1 ? lag_y1 : lag_y2;
      t.pairs[lag] += w;
      t.sum_xy[lag] += products;
      t.sum_x[lag] += s;
      t.sum_y[lag] += sum_next;
    }

    // Tenengrad: Sobel gradient energy (the offset cancels in the differences).
    if (y >= 1 && y + 1 < g.height && sx1 > sx0) {
      const float* rm = row(y - 1);
      const float* rp = row(y + 1);
      float energy = 0;
#pragma omp simd reduction(+ : energy)
      for (int x = sx0; x < sx1; ++x) {
        const float gx = (rm[x + 1] + 2 * r0[x + 1] + rp[x + 1]) - (rm[x - 1] + 2 * r0[x - 1] + rp[x - 1]);
        const float gy = (rp[x - 1] + 2 * rp[x] + rp[x + 1]) - (rm[x - 1] + 2 * rm[x] + rm[x + 1]);
        energy += gx * gx + gy * gy;
      }
      t.sobel += energy;
      t.sobel_n += sx1 - sx0;
    }

    if ((y - y0) % kSampleStep == kSampleStep / 2)
      for (int xs = x0 + kSampleStep / 2; xs < x1; xs += kSampleStep) sample[samples++] = raw[xs];
  }
  if (samples == 0) sample[samples++] = image.row<T>(y0)[x0];  // a sliver of a tile
  tile_background<T>(image, x0, x1, y0, y1, samples, t, scratch);
}

template <typename T>
void accumulate_all(const Image& image, const TileGrid& g, int full_scale, std::vector<std::uint32_t>& histogram,
                    std::vector<TileSums>& tiles, TileScratch& scratch) {
  // Tile rows outer, so a band of tile + 2 image rows stays in cache while its tiles are done.
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      accumulate_tile<T>(image, g, i, j, full_scale, histogram.data(), tiles[static_cast<std::size_t>(i + g.nx * j)],
                         scratch);
}

// Horizontal maximum of each pixel and its left and right neighbours, for x in [1, w - 1).
template <typename T>
[[gnu::always_inline]] inline void row_max3(const T* r, T* out, int w) {
#pragma omp simd
  for (int x = 1; x < w - 1; ++x) {
    const T a = r[x - 1] > r[x] ? r[x - 1] : r[x];
    out[x] = a > r[x + 1] ? a : r[x + 1];
  }
}

// Local maxima of row r0 over x in [x0, x1): `above` and `below` are the 3-px horizontal maxima
// of the rows above and below. A peak is strictly above the four neighbours before it in raster
// order (the row above and its left neighbour) and at least equal to the four after it.
template <typename T>
[[gnu::always_inline]] inline std::uint32_t row_peaks(const T* r0, const T* above, const T* below, T floor, int x0,
                                                       int x1) {
  std::uint32_t c = 0;
#pragma omp simd reduction(+ : c)
  for (int x = x0; x < x1; ++x) {
    const T v = r0[x];
    const T before = above[x] > r0[x - 1] ? above[x] : r0[x - 1];
    const T after = below[x] > r0[x + 1] ? below[x] : r0[x + 1];
    c += static_cast<std::uint32_t>((v >= floor) & (v > before) & (v >= after));
  }
  return c;
}

// The whole frame row by row (rows stream through the cache once), each row's tiles in turn;
// the horizontal 3-px maxima of three consecutive rows are kept in a ring, so every pixel is
// compared with two maxima and two neighbours instead of eight neighbours.
template <typename T>
[[gnu::always_inline]] inline std::uint64_t count_all(const Image& image, const TileGrid& g,
                                                      const std::vector<std::int32_t>& thresholds,
                                                      std::vector<std::uint32_t>& per_tile, T* ring) {
  constexpr std::int32_t top = std::numeric_limits<T>::max();
  std::fill(per_tile.begin(), per_tile.end(), 0u);
  const int w = g.width;
  const auto ring_row = [&](int y) { return ring + static_cast<std::ptrdiff_t>(y % 3) * w; };
  row_max3<T>(image.row<T>(0), ring_row(0), w);
  row_max3<T>(image.row<T>(1), ring_row(1), w);
  std::uint64_t total = 0;
  for (int y = 1; y + 1 < g.height; ++y) {
    row_max3<T>(image.row<T>(y + 1), ring_row(y + 1), w);
    const T* r0 = image.row<T>(y);
    const T* above = ring_row(y - 1);
    const T* below = ring_row(y + 1);
    const int j = y / g.tile < g.ny ? y / g.tile : g.ny - 1;
    for (int i = 0; i < g.nx; ++i) {
      const auto n = static_cast<std::size_t>(i + g.nx * j);
      const std::int32_t threshold = thresholds[n];
      if (threshold >= top) continue;  // nothing can exceed it
      // v > threshold  <=>  v >= threshold + 1; a negative threshold lets every value pass.
      const T floor = threshold < 0 ? T{0} : static_cast<T>(threshold + 1);
      const int x0 = std::max(g.x0(i), 1), x1 = std::min(g.x1(i), w - 1);
      const std::uint32_t c = row_peaks<T>(r0, above, below, floor, x0, x1);
      per_tile[n] += c;
      total += c;
    }
  }
  return total;
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] std::uint64_t count_all_u16(
    const Image& image, const TileGrid& g, const std::vector<std::int32_t>& thresholds,
    std::vector<std::uint32_t>& per_tile, std::uint16_t* ring) {
  return count_all<std::uint16_t>(image, g, thresholds, per_tile, ring);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] std::uint64_t count_all_u8(
    const Image& image, const TileGrid& g, const std::vector<std::int32_t>& thresholds,
    std::vector<std::uint32_t>& per_tile, std::uint8_t* ring) {
  return count_all<std::uint8_t>(image, g, thresholds, per_tile, ring);
}

}  // namespace

std::span<const std::uint32_t> histogram_halves(std::vector<std::uint32_t>& histogram, std::size_t values) {
  for (std::size_t v = 0; v < values; ++v) histogram[v] += histogram[kHistogramStride + v];
  return {histogram.data(), values};
}

double TileSums::variance() const {
  if (n <= 0) return 0.0;
  const double m = sum / n;
  return std::max(0.0, sumsq / n - m * m);
}

double TileSums::covariance(int lag) const {
  const double p = pairs[lag];
  if (p <= 0 || n <= 0) return 0.0;
  const double m = sum / n;  // about the tile mean, in offset units like the sums
  return (sum_xy[lag] - m * (sum_x[lag] + sum_y[lag])) / p + m * m;
}

void accumulate(const Image& image, const TileGrid& grid, int full_scale, std::vector<std::uint32_t>& histogram,
                std::vector<TileSums>& tiles, TileScratch& scratch) {
  if (image.type() == SampleType::u8)
    accumulate_all<std::uint8_t>(image, grid, full_scale, histogram, tiles, scratch);
  else
    accumulate_all<std::uint16_t>(image, grid, full_scale, histogram, tiles, scratch);
}

std::uint64_t count_maxima(const Image& image, const TileGrid& grid, const std::vector<std::int32_t>& thresholds,
                           std::vector<std::uint32_t>& per_tile, std::vector<std::uint16_t>& ring) {
  ring.resize(3 * static_cast<std::size_t>(grid.width));  // no allocation once sized
  if (image.type() == SampleType::u8)
    return count_all_u8(image, grid, thresholds, per_tile, reinterpret_cast<std::uint8_t*>(ring.data()));
  return count_all_u16(image, grid, thresholds, per_tile, ring.data());
}

}  // namespace tomorig::quicklook::detail
