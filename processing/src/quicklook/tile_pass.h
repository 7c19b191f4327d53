#pragma once
// The passes of the quick-look statistics over a frame (statistics.h):
//   scan_tiles():     every pixel, tile by tile: the full-resolution histogram, each tile's
//                     saturated count, and each tile's background level and noise (from a
//                     quarter of its pixels);
//   measure_detail(): the sample tiles only (DetailLattice): moments, autocovariance sums at
//                     lags 1 and 2 along x and y, and Sobel energy, for d_tau, the
//                     autocovariance ppp and the focus map;
//   count_maxima():   every pixel: local maxima above each tile's threshold.
// Every loop over pixels is written for the compiler to vectorise (`omp simd` reductions); the
// heaviest are compiled twice, for x86-64-v3 (AVX2, FMA) and the baseline, and the CPU picks at
// run time. Nothing allocates once the scratch is sized.
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

// The sample tiles the per-pixel-expensive figures are measured on: one tile in every
// step x step block of tiles (step 1: every tile), step the smallest that leaves at most
// `max_tiles` blocks. Block (ci, cj) is measured on tile (tile_i(ci), tile_j(cj)), the one nearest
// the block's centre, so the sample spreads evenly over the frame and a block map (the focus
// map) has a value for every block.
struct DetailLattice {
  int step = 1, nx = 0, ny = 0;  // blocks per row and column
  int tiles_x = 0, tiles_y = 0;  // the grid's

  DetailLattice() = default;
  DetailLattice(const TileGrid& grid, int max_tiles);
  int count() const { return nx * ny; }
  int tile_i(int ci) const { return ci * step + step / 2 < tiles_x ? ci * step + step / 2 : tiles_x - 1; }
  int tile_j(int cj) const { return cj * step + step / 2 < tiles_y ? cj * step + step / 2 : tiles_y - 1; }
  // Index into the grid's tiles of block c's sample tile.
  std::size_t tile_of(int c) const {
    return static_cast<std::size_t>(tile_i(c % nx) + tiles_x * tile_j(c / nx));
  }
};

// What every tile contributes.
struct TileLevel {
  double pixels = 0;
  double saturated = 0;
  // The tile's background: half-sample mode of its histogram and the noise below it (counts).
  double background = 0, noise = 0;
};

// Autocovariance lags, in this order.
enum Lag { lag_x1 = 0, lag_x2 = 1, lag_y1 = 2, lag_y2 = 3, lag_count = 4 };

// Sums of one sample tile. Pixel values enter as d = value - offset (the tile's first pixel),
// so that float row sums stay accurate on a high black level.
struct DetailSums {
  double offset = 0;
  double n = 0, sum = 0, sumsq = 0;
  double sobel = 0, sobel_n = 0;  // sum of Gx^2 + Gy^2 over pixels with a full 3 x 3 neighbourhood
  // Pairs (d(p), d(p + lag)) inside the tile: count, sum of products, sums of either member.
  double pairs[lag_count] = {}, sum_xy[lag_count] = {}, sum_x[lag_count] = {}, sum_y[lag_count] = {};

  double mean() const { return n > 0 ? offset + sum / n : 0.0; }
  double variance() const;
  // Covariance at `lag` about the tile mean (0 if the tile has no such pairs).
  double covariance(int lag) const;
};

// Every `kSampleStep`-th pixel of every `kSampleStep`-th row of a tile is sampled to place the
// window of the tile's own histogram: 64 samples for a 64 px tile.
constexpr int kSampleStep = 8;
// The tile histogram: bins, and how many of them lie below the sample's 5th percentile.
constexpr int kTileBins = 256;  // bin numbers fit a byte (tile_pass.cpp)
constexpr int kTileBinsBelow = 64;

// Scratch of the passes, sized by the first frame (reserve()) and reused.
struct TileScratch {
  std::vector<float> tile;               // (tile + 3) x (tile + 2): a tile, its border and a pad column as floats
  std::vector<float> row_sums;           // tile entries: a sample tile's row sums
  std::vector<float> zeros;              // tile + 2 entries of 0: the row past a tile's last
  std::vector<std::uint16_t> sample;     // (tile / kSampleStep + 1)^2 entries per tile of a band
  std::vector<std::uint32_t> band_samples, band_saturated;  // per tile of a band
  std::vector<std::uint32_t> histogram;  // 2 x kTileBins entries (two halves, added up)
  std::vector<std::uint8_t> bin_index;   // tile / 2 + 1: a sampled row's bin numbers
  std::vector<std::uint16_t> rank_below, rank_at;  // a tile sample's ranks (tile_pass.cpp)
  std::vector<std::uint16_t> maxima_rows;  // 3 x width: count_maxima's ring of row maxima

  void reserve(const TileGrid& grid);
};

// The frame histogram is kept as two halves (even and odd columns) of this many entries each,
// enough for 16-bit samples; histogram_halves() adds them up.
constexpr std::size_t kHistogramStride = 65536;

// Every tile. `histogram` must hold 2 * kHistogramStride entries, zero on entry (the sums of
// even and odd columns); `tiles` must hold grid.count() entries and is overwritten.
void scan_tiles(const Image& image, const TileGrid& grid, int full_scale, std::vector<std::uint32_t>& histogram,
                std::vector<TileLevel>& tiles, TileScratch& scratch);

// The lattice's sample tiles; `sums` (lattice.count() entries, block order) is overwritten.
void measure_detail(const Image& image, const TileGrid& grid, const DetailLattice& lattice,
                    std::vector<DetailSums>& sums, TileScratch& scratch);

// Adds the odd-column half of `histogram` into the even one and returns the latter's first
// `values` entries (256 for 8-bit samples, 65536 for 16-bit).
std::span<const std::uint32_t> histogram_halves(std::vector<std::uint32_t>& histogram, std::size_t values);

// Counts pixels (with a full 3 x 3 neighbourhood) that exceed their tile's threshold (integer
// counts: a pixel counts if value > threshold) and are the maximum of their 3 x 3
// neighbourhood; of equal neighbours the first in raster order wins, so a plateau counts
// once. Returns the total; `per_tile` (grid.count() entries) receives the tile counts.
std::uint64_t count_maxima(const Image& image, const TileGrid& grid, const std::vector<std::int32_t>& thresholds,
                           std::vector<std::uint32_t>& per_tile, TileScratch& scratch);

}  // namespace tomorig::quicklook::detail
