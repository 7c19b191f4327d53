#pragma once
// The two passes of the quick-look statistics over a frame, tile by tile (statistics.h):
//   accumulate():   histogram, moments, saturation, Sobel energy, autocovariance sums at lags
//                   1 and 2 along x and y, and each tile's background level and noise;
//   count_maxima(): local maxima above each tile's threshold.
// Both walk the image once, tile by tile, in loops the compiler vectorises (`omp simd`
// reductions); neither allocates.
#include <cstdint>
#include <span>
#include <vector>

#include "tomorig/core/image.h"

namespace tomorig::quicklook::detail {

// The tiling of an image: tiles of `tile` px, the last row and column possibly smaller.
struct TileGrid {
  int width = 0, height = 0, tile = 0;
  int nx = 0, ny = 0;

  TileGrid() = default;
  TileGrid(int w, int h, int t) : width(w), height(h), tile(t), nx((w + t - 1) / t), ny((h + t - 1) / t) {}
  int count() const { return nx * ny; }
  int x0(int i) const { return i * tile; }
  int x1(int i) const { return i + 1 < nx ? (i + 1) * tile : width; }
  int y0(int j) const { return j * tile; }
  int y1(int j) const { return j + 1 < ny ? (j + 1) * tile : height; }
};

// Autocovariance lags, in this order.
enum Lag { lag_x1 = 0, lag_x2 = 1, lag_y1 = 2, lag_y2 = 3, lag_count = 4 };

// Sums of one tile. Pixel values enter as d = value - offset (the tile's first pixel), so that
// float row sums stay accurate on a high black level.
struct TileSums {
  double offset = 0;
  double n = 0, sum = 0, sumsq = 0;
  double saturated = 0;
  double sobel = 0, sobel_n = 0;  // sum of Gx^2 + Gy^2 over pixels with a full 3 x 3 neighbourhood
  // Pairs (d(p), d(p + lag)) inside the tile: count, sum of products, sums of either member.
  double pairs[lag_count] = {}, sum_xy[lag_count] = {}, sum_x[lag_count] = {}, sum_y[lag_count] = {};
  // The tile's background: half-sample mode of its histogram and the noise below it (counts).
  double background = 0, noise = 0;

  double mean() const { return n > 0 ? offset + sum / n : 0.0; }
  double variance() const;
  // Covariance at `lag` about the tile mean (0 if the tile has no such pairs).
  double covariance(int lag) const;
};

// Every `kSampleStep`-th pixel of every `kSampleStep`-th row of a tile is sampled to place the
// window of the tile's own histogram: 64 samples for a 64 px tile.
constexpr int kSampleStep = 8;
// The tile histogram: bins, and how many of them lie below the sample's 5th percentile.
constexpr int kTileBins = 256;
constexpr int kTileBinsBelow = 64;

// Scratch of one tile's background estimate.
struct TileScratch {
  std::vector<float> tile;               // (tile + 2)^2 entries: a tile and its border as floats
  std::vector<std::uint16_t> sample;     // (tile / kSampleStep + 1)^2 entries
  std::vector<std::uint32_t> histogram;  // kTileBins entries
};

// The frame histogram is kept as two halves (even and odd columns) of this many entries each,
// enough for 16-bit samples; histogram_halves() adds them up.
constexpr std::size_t kHistogramStride = 65536;

// Pass 1. `histogram` must hold 2 * kHistogramStride entries, zero on entry (the sums of even
// and odd columns); `tiles` must hold grid.count() entries and is overwritten.
void accumulate(const Image& image, const TileGrid& grid, int full_scale, std::vector<std::uint32_t>& histogram,
                std::vector<TileSums>& tiles, TileScratch& scratch);

// Adds the odd-column half of `histogram` into the even one and returns the latter's first
// `values` entries (256 for 8-bit samples, 65536 for 16-bit).
std::span<const std::uint32_t> histogram_halves(std::vector<std::uint32_t>& histogram, std::size_t values);

// Pass 2. Counts pixels (with a full 3 x 3 neighbourhood) that exceed their tile's threshold
// (integer counts: a pixel counts if value > threshold) and are the maximum of their 3 x 3
// neighbourhood; of equal neighbours the first in raster order wins, so a plateau counts
// once. Returns the total; `per_tile` (grid.count() entries) receives the tile counts. `ring`
// is scratch (three rows of horizontal maxima), sized on first use.
std::uint64_t count_maxima(const Image& image, const TileGrid& grid, const std::vector<std::int32_t>& thresholds,
                           std::vector<std::uint32_t>& per_tile, std::vector<std::uint16_t>& ring);

}  // namespace tomorig::quicklook::detail
