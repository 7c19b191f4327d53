#include "tile_pass.h"

#include <algorithm>
#include <cmath>

#include "histogram_stats.h"

namespace tomorig::quicklook::detail {
namespace {

template <typename T>
float value_at(const T* row, int x, float offset) {
  return static_cast<float>(row[x]) - offset;
}

// Sum over x in [x0, x1) of (a[x] - offset) * (b[x + shift] - offset), and of (b[x + shift] -
// offset). Float partial sums over one tile row: at most a few hundred terms.
template <typename T>
void row_products(const T* a, const T* b, int x0, int x1, int shift, float offset, float& products, float& sum_b) {
  float p = 0, s = 0;
#pragma omp simd reduction(+ : p, s)
  for (int x = x0; x < x1; ++x) {
    const float db = static_cast<float>(b[x + shift]) - offset;
    p += (static_cast<float>(a[x]) - offset) * db;
    s += db;
  }
  products = p;
  sum_b = s;
}

// The tile's background level and noise from its own histogram (every other row): a window of
// kTileBins bins placed by the sampled 5th percentile, the bins wide enough that the sampled
// 5th to 50th percentiles span about 32 of them; half-sample mode and lower-half noise as for
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
  const int width = std::max(1, (p50 - p5 + 31) / 32);
  const int origin = p5 - kTileBinsBelow * width;

  std::uint32_t* h = scratch.histogram.data();
  std::fill(h, h + kTileBins, 0u);
  for (int y = y0; y < y1; y += 2) {
    const T* r = image.row<T>(y);
    for (int x = x0; x < x1; ++x) {
      const int d = static_cast<int>(r[x]) - origin;
      ++h[d < 0 ? 0 : std::min(kTileBins - 1, d / width)];
    }
  }
  const std::span<const std::uint32_t> bins(h, kTileBins);
  const double mode = half_sample_mode(bins);
  // Bin b holds values origin + b * width .. origin + (b + 1) * width - 1.
  t.background = origin + mode * width + 0.5 * (width - 1);
  t.noise = lower_half_sigma(bins, mode) * width;
}

template <typename T>
void accumulate_tile(const Image& image, const TileGrid& g, int i, int j, int full_scale, std::uint32_t* histogram,
                     TileSums& t, TileScratch& scratch) {
  std::vector<std::uint16_t>& sample = scratch.sample;
  const int x0 = g.x0(i), x1 = g.x1(i), y0 = g.y0(j), y1 = g.y1(j);
  const int w = x1 - x0;
  t = TileSums{};
  const float offset = static_cast<float>(image.row<T>(y0)[x0]);
  t.offset = offset;
  // Sobel needs the 3 x 3 neighbourhood inside the image (it may reach into other tiles).
  const int sx0 = std::max(x0, 1), sx1 = std::min(x1, g.width - 1);
  std::size_t samples = 0;

  for (int y = y0; y < y1; ++y) {
    const T* r0 = image.row<T>(y);

    float s = 0, ss = 0;
    int saturated = 0;
#pragma omp simd reduction(+ : s, ss, saturated)
    for (int x = x0; x < x1; ++x) {
      const float d = static_cast<float>(r0[x]) - offset;
      s += d;
      ss += d * d;
      saturated += static_cast<int>(r0[x]) >= full_scale ? 1 : 0;
    }
    for (int x = x0; x < x1; ++x) ++histogram[r0[x]];
    t.n += w;
    t.sum += s;
    t.sumsq += ss;
    t.saturated += saturated;

    // Lags along x: pairs (x, x + 1) and (x, x + 2) inside the tile. The sums of either member
    // are the row sum without the end pixels.
    float products = 0, unused = 0;
    if (w > 1) {
      row_products(r0, r0, x0, x1 - 1, 1, offset, products, unused);
      t.pairs[lag_x1] += w - 1;
      t.sum_xy[lag_x1] += products;
      t.sum_x[lag_x1] += s - value_at(r0, x1 - 1, offset);
      t.sum_y[lag_x1] += s - value_at(r0, x0, offset);
    }
    if (w > 2) {
      row_products(r0, r0, x0, x1 - 2, 2, offset, products, unused);
      t.pairs[lag_x2] += w - 2;
      t.sum_xy[lag_x2] += products;
      t.sum_x[lag_x2] += s - value_at(r0, x1 - 1, offset) - value_at(r0, x1 - 2, offset);
      t.sum_y[lag_x2] += s - value_at(r0, x0, offset) - value_at(r0, x0 + 1, offset);
    }
    // Lags along y: rows y + 1 and y + 2 of the same tile.
    for (int step = 1; step <= 2; ++step) {
      if (y + step >= y1) break;
      float sum_next = 0;
      row_products(r0, image.row<T>(y + step), x0, x1, 0, offset, products, sum_next);
      const int lag = step == 1 ? lag_y1 : lag_y2;
      t.pairs[lag] += w;
      t.sum_xy[lag] += products;
      t.sum_x[lag] += s;
      t.sum_y[lag] += sum_next;
    }

    // Tenengrad: Sobel gradient energy.
    if (y >= 1 && y + 1 < g.height && sx1 > sx0) {
      const T* rm = image.row<T>(y - 1);
      const T* rp = image.row<T>(y + 1);
      float energy = 0;
#pragma omp simd reduction(+ : energy)
      for (int x = sx0; x < sx1; ++x) {
        const int gx = (rm[x + 1] + 2 * r0[x + 1] + rp[x + 1]) - (rm[x - 1] + 2 * r0[x - 1] + rp[x - 1]);
        const int gy = (rp[x - 1] + 2 * rp[x] + rp[x + 1]) - (rm[x - 1] + 2 * rm[x] + rm[x + 1]);
        const float fx = static_cast<float>(gx), fy = static_cast<float>(gy);
        energy += fx * fx + fy * fy;
      }
      t.sobel += energy;
      t.sobel_n += sx1 - sx0;
    }

    if ((y - y0) % kSampleStep == kSampleStep / 2)
      for (int x = x0 + kSampleStep / 2; x < x1; x += kSampleStep) sample[samples++] = r0[x];
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

template <typename T>
std::uint32_t maxima_in_tile(const Image& image, const TileGrid& g, int i, int j, std::int32_t threshold) {
  const int x0 = std::max(g.x0(i), 1), x1 = std::min(g.x1(i), g.width - 1);
  const int y0 = std::max(g.y0(j), 1), y1 = std::min(g.y1(j), g.height - 1);
  std::uint32_t count = 0;
  for (int y = y0; y < y1; ++y) {
    const T* rm = image.row<T>(y - 1);
    const T* r0 = image.row<T>(y);
    const T* rp = image.row<T>(y + 1);
    std::uint32_t c = 0;
#pragma omp simd reduction(+ : c)
    for (int x = x0; x < x1; ++x) {
      const T v = r0[x];
      // Strictly above the neighbours before it in raster order, at least equal to those after.
      const bool peak = (static_cast<std::int32_t>(v) > threshold) & (v > rm[x - 1]) & (v > rm[x]) & (v > rm[x + 1]) &
                        (v > r0[x - 1]) & (v >= r0[x + 1]) & (v >= rp[x - 1]) & (v >= rp[x]) & (v >= rp[x + 1]);
      c += peak ? 1u : 0u;
    }
    count += c;
  }
  return count;
}

template <typename T>
std::uint64_t count_all(const Image& image, const TileGrid& g, const std::vector<std::int32_t>& thresholds,
                        std::vector<std::uint32_t>& per_tile) {
  std::uint64_t total = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const auto n = static_cast<std::size_t>(i + g.nx * j);
      per_tile[n] = maxima_in_tile<T>(image, g, i, j, thresholds[n]);
      total += per_tile[n];
    }
  return total;
}

}  // namespace

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
                           std::vector<std::uint32_t>& per_tile) {
  if (image.type() == SampleType::u8) return count_all<std::uint8_t>(image, grid, thresholds, per_tile);
  return count_all<std::uint16_t>(image, grid, thresholds, per_tile);
}

}  // namespace tomorig::quicklook::detail
