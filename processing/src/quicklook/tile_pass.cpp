#include "tile_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "histogram_stats.h"

namespace tomorig::quicklook::detail {
namespace {

// The samples' k_low-th and k_high-th smallest values (0-based), exactly: value v[i] is the k-th
// when fewer than k + 1 values lie below it and at least k + 1 at or below it. For a tile's 64
// samples the n^2 comparisons run in 16-bit vector lanes without a branch, a fraction of the
// time nth_element took; larger samples (tiles over 128 px) use nth_element. `below` and `at`
// are scratch of kRankSelectMax entries each.
constexpr std::size_t kRankSelectMax = 256;
static_assert(kTileBins <= 256, "tile_background keeps bin numbers in bytes");

[[gnu::always_inline]] inline void select_two(std::uint16_t* v, std::size_t n, std::size_t k_low,
                                              std::size_t k_high, int& low, int& high, std::uint16_t* below,
                                              std::uint16_t* at) {
  if (n > kRankSelectMax) {
    std::nth_element(v, v + k_high, v + n);
    high = v[k_high];
    std::nth_element(v, v + k_low, v + k_high);
    low = v[k_low];
    return;
  }
  // Ranks of all values at once: one sweep over the vector of all i per value j (no horizontal
  // sums): below[i] = #{j: v[j] < v[i]}, at[i] = #{j: v[j] == v[i]} (n <= 256: no overflow).
  const auto count = static_cast<int>(n);
  std::fill(below, below + count, std::uint16_t{0});
  std::fill(at, at + count, std::uint16_t{0});
  for (int j = 0; j < count; ++j) {
    const std::uint16_t x = v[j];
#pragma omp simd
    for (int i = 0; i < count; ++i) {
      below[i] += static_cast<std::uint16_t>(x < v[i]);
      at[i] += static_cast<std::uint16_t>(x == v[i]);
    }
  }
  for (int i = 0; i < count; ++i) {
    const std::size_t first = below[i], past = static_cast<std::size_t>(below[i] + at[i]);
    if (first <= k_low && k_low < past) low = v[i];
    if (first <= k_high && k_high < past) high = v[i];
  }
}

// The tile's background level and noise from its own histogram (every other pixel of every other
// row: 1024 of a 64 px tile): a window of kTileBins bins placed by the sampled 5th percentile,
// the bins (a power of two counts wide) narrow enough that the sampled 5th to 50th percentiles
// span 16 to 32 of them; half-sample mode and lower-half noise as for
// the whole frame (histogram_stats.h).
template <typename T>
[[gnu::always_inline]] inline void tile_background(const Image& image, int x0, int x1, int y0, int y1,
                                                   std::uint16_t* sample, std::size_t samples, TileLevel& t,
                                                   TileScratch& scratch) {
  const auto k5 = static_cast<std::size_t>(0.05 * static_cast<double>(samples - 1));
  const auto k50 = static_cast<std::size_t>(0.50 * static_cast<double>(samples - 1));
  int p5 = 0, p50 = 0;
  select_two(sample, samples, k5, k50, p5, p50, scratch.rank_below.data(), scratch.rank_at.data());
  // Bins of a power-of-two width: a shift, not a division, per pixel.
  int shift = 0;
  while ((32 << shift) < p50 - p5) ++shift;
  const int width = 1 << shift;
  const int origin = p5 - kTileBinsBelow * width;

  // Each sampled row's bin numbers first (a vector loop), then the increments, alternately
  // into two histograms (as for the frame's), added up after.
  std::uint32_t* h = scratch.histogram.data();
  std::uint32_t* h2 = h + kTileBins;
  std::fill(h, h + 2 * kTileBins, 0u);
  std::uint8_t* index = scratch.bin_index.data();
  const int m = (x1 - x0 + 1) / 2;  // columns x0, x0 + 2, ...
  for (int y = y0; y < y1; y += 2) {
    const T* r = image.row<T>(y) + x0;
#pragma omp simd
    for (int k = 0; k < m; ++k) {
      const int d = static_cast<int>(r[2 * k]) - origin;
      const int b = d < 0 ? 0 : d >> shift;
      index[k] = static_cast<std::uint8_t>(b < kTileBins - 1 ? b : kTileBins - 1);
    }
    int k = 0;
    for (; k + 1 < m; k += 2) {
      ++h[index[k]];
      ++h2[index[k + 1]];
    }
    if (k < m) ++h[index[k]];
  }
  for (int b = 0; b < kTileBins; ++b) h[b] += h2[b];
  const std::span<const std::uint32_t> bins(h, kTileBins);
  const double rough = half_sample_mode(bins);
  const double mode = refine_mode(bins, rough, lower_half_sigma(bins, rough));
  // Bin b holds values origin + b * width .. origin + (b + 1) * width - 1.
  t.background = origin + mode * width + 0.5 * (width - 1);
  t.noise = lower_half_sigma(bins, mode) * width;
}

// scan_tiles() for one band of tiles: its image rows whole, in order (the hardware prefetcher
// streams them; tile by tile would jump a row stride every tile width), then each tile's
// background from the band, which is still in cache.
template <typename T>
[[gnu::always_inline]] inline void scan_band(const Image& image, const TileGrid& g, int j, int full_scale,
                                             std::uint32_t* histogram, TileLevel* tiles, TileScratch& scratch) {
  const int y0 = g.y0(j), y1 = g.y1(j), w = g.width;
  const T saturation = static_cast<T>(std::min<int>(full_scale, std::numeric_limits<T>::max()));
  std::uint32_t* saturated = scratch.band_saturated.data();
  std::uint32_t* samples = scratch.band_samples.data();
  std::uint16_t* sample = scratch.sample.data();
  const std::size_t per_tile = scratch.sample.size() / static_cast<std::size_t>(g.nx);
  std::fill(saturated, saturated + g.nx, 0u);
  std::fill(samples, samples + g.nx, 0u);
  std::uint32_t* odd = histogram + kHistogramStride;
  for (int y = y0; y < y1; ++y) {
    const T* raw = image.row<T>(y);
    for (int i = 0; i < g.nx; ++i) {
      std::uint32_t c = 0;
#pragma omp simd reduction(+ : c)
      for (int x = g.x0(i); x < g.x1(i); ++x) c += raw[x] >= saturation ? 1u : 0u;
      saturated[i] += c;
    }
    // Two histograms for even and odd columns: neighbouring pixels often share a value, and
    // one counter would make every increment wait for the previous one.
    int x = 0;
    for (; x + 1 < w; x += 2) {
      ++histogram[raw[x]];
      ++odd[raw[x + 1]];
    }
    if (x < w) ++histogram[raw[x]];
    if ((y - y0) % kSampleStep == kSampleStep / 2)
      for (int i = 0; i < g.nx; ++i) {
        std::uint16_t* mine = sample + per_tile * static_cast<std::size_t>(i);
        for (int xs = g.x0(i) + kSampleStep / 2; xs < g.x1(i); xs += kSampleStep) mine[samples[i]++] = raw[xs];
      }
  }
  for (int i = 0; i < g.nx; ++i) {
    const int x0 = g.x0(i), x1 = g.x1(i);
    TileLevel& t = tiles[i + g.nx * j];
    t = TileLevel{};
    t.pixels = static_cast<double>(x1 - x0) * (y1 - y0);
    t.saturated = saturated[i];
    std::uint16_t* mine = sample + per_tile * static_cast<std::size_t>(i);
    if (samples[i] == 0) mine[samples[i]++] = image.row<T>(y0)[x0];  // a sliver of a tile
    tile_background<T>(image, x0, x1, y0, y1, mine, samples[i], t, scratch);
  }
}

template <typename T>
[[gnu::always_inline]] inline void scan_all(const Image& image, const TileGrid& g, int full_scale,
                                            std::uint32_t* histogram, TileLevel* tiles, TileScratch& scratch) {
  for (int j = 0; j < g.ny; ++j) scan_band<T>(image, g, j, full_scale, histogram, tiles, scratch);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void scan_all_u16(const Image& image, const TileGrid& g,
                                                                      int full_scale, std::uint32_t* histogram,
                                                                      TileLevel* tiles, TileScratch& scratch) {
  scan_all<std::uint16_t>(image, g, full_scale, histogram, tiles, scratch);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void scan_all_u8(const Image& image, const TileGrid& g,
                                                                     int full_scale, std::uint32_t* histogram,
                                                                     TileLevel* tiles, TileScratch& scratch) {
  scan_all<std::uint8_t>(image, g, full_scale, histogram, tiles, scratch);
}

// Eight floats in a vector register (AVX in the x86-64-v3 clones, two SSE halves otherwise).
// Explicit vectors, not `omp simd` reductions: with six sums GCC kept a scalar loop. They are
// only passed between inlined functions of this file, so the ABI note GCC gives for 32-byte
// vectors without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"
using Float8 = float __attribute__((vector_size(32)));

[[gnu::always_inline]] inline Float8 load8(const float* p) {
  Float8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

[[gnu::always_inline]] inline float sum8(Float8 v) {
  return ((v[0] + v[1]) + (v[2] + v[3])) + ((v[4] + v[5]) + (v[6] + v[7]));
}

struct RowSums {
  float s, ss, px1, px2, py1, py2;
};

// Over x in [x0, x1) of row r0 (r1, r2: the next two rows): sum, sum of squares, and the
// products with the pixel 1 and 2 columns on and 1 and 2 rows down. Reads r0 up to x1 + 1.
[[gnu::always_inline]] inline RowSums row_sums_and_lags(const float* r0, const float* r1, const float* r2, int x0,
                                                       int x1) {
  Float8 s{}, ss{}, px1{}, px2{}, py1{}, py2{};
  int x = x0;
  for (; x + 8 <= x1; x += 8) {
    const Float8 d = load8(r0 + x);
    s += d;
    ss += d * d;
    px1 += d * load8(r0 + x + 1);
    px2 += d * load8(r0 + x + 2);
    py1 += d * load8(r1 + x);
    py2 += d * load8(r2 + x);
  }
  RowSums out{sum8(s), sum8(ss), sum8(px1), sum8(px2), sum8(py1), sum8(py2)};
  for (; x < x1; ++x) {
    const float d = r0[x];
    out.s += d;
    out.ss += d * d;
    out.px1 += d * r0[x + 1];
    out.px2 += d * r0[x + 2];
    out.py1 += d * r1[x];
    out.py2 += d * r2[x];
  }
  return out;
}

// Sobel gradient energy Gx^2 + Gy^2 summed over x in [x0, x1) of row r0 (rm, rp: the rows
// above and below), separably: column sums and differences first.
[[gnu::always_inline]] inline float sobel_energy(const float* rm, const float* r0, const float* rp, int x0, int x1) {
  Float8 e{};
  int x = x0;
  const Float8 two = {2, 2, 2, 2, 2, 2, 2, 2};
  for (; x + 8 <= x1; x += 8) {
    const Float8 ml = load8(rm + x - 1), mc = load8(rm + x), mr = load8(rm + x + 1);
    const Float8 cl = load8(r0 + x - 1), cr = load8(r0 + x + 1);
    const Float8 pl = load8(rp + x - 1), pc = load8(rp + x), pr = load8(rp + x + 1);
    const Float8 gx = (mr + two * cr + pr) - (ml + two * cl + pl);
    const Float8 gy = (pl + two * pc + pr) - (ml + two * mc + mr);
    e += gx * gx + gy * gy;
  }
  float energy = sum8(e);
  for (; x < x1; ++x) {
    const float gx = (rm[x + 1] + 2 * r0[x + 1] + rp[x + 1]) - (rm[x - 1] + 2 * r0[x - 1] + rp[x - 1]);
    const float gy = (rp[x - 1] + 2 * rp[x] + rp[x + 1]) - (rm[x - 1] + 2 * rm[x] + rm[x + 1]);
    energy += gx * gx + gy * gy;
  }
  return energy;
}

// One sample tile of measure_detail().
template <typename T>
[[gnu::always_inline]] inline void detail_tile(const Image& image, const TileGrid& g, int i, int j, DetailSums& t,
                                               TileScratch& scratch) {
  const int x0 = g.x0(i), x1 = g.x1(i), y0 = g.y0(j), y1 = g.y1(j);
  const int w = x1 - x0;
  t = DetailSums{};
  const float offset = static_cast<float>(image.row<T>(y0)[x0]);
  t.offset = offset;

  // The tile and a 1 px border (for Sobel) as floats minus the offset, converted once for all
  // the sums below. Integer counts up to 65535 are exact in float. Fixed layout: buffer column
  // x - x0 + 1, row y - y0 + 1; a border outside the image and the pad column after the right
  // border hold zeros.
  const int stride = g.tile + 3;
  float* buffer = scratch.tile.data();
  const int bx0 = std::max(x0 - 1, 0), bx1 = std::min(x1 + 1, g.width);
  const int by0 = std::max(y0 - 1, 0), by1 = std::min(y1 + 1, g.height);
  // Row y of the buffer, indexed by image column.
  const auto row = [&](int y) { return buffer + static_cast<std::ptrdiff_t>(y - y0 + 1) * stride - (x0 - 1); };
  for (int y = y0 - 1; y <= y1; ++y) {
    float* dst = row(y);
    if (y < by0 || y >= by1) {
      std::fill(dst + x0 - 1, dst + x1 + 2, 0.0f);
      continue;
    }
    const T* src = image.row<T>(y);
#pragma omp simd
    for (int x = bx0; x < bx1; ++x) dst[x] = static_cast<float>(src[x]) - offset;
    if (bx0 == x0) dst[x0 - 1] = 0.0f;
    if (bx1 == x1) dst[x1] = 0.0f;
    dst[x1 + 1] = 0.0f;
  }
  const float* zeros = scratch.zeros.data() - x0;  // the rows past the tile's last, for the y lags
  float* row_sums = scratch.row_sums.data();
  // Sobel needs the 3 x 3 neighbourhood inside the image (it may reach into other tiles).
  const int sx0 = std::max(x0, 1), sx1 = std::min(x1, g.width - 1);

  for (int y = y0; y < y1; ++y) {
    const float* r0 = row(y);
    const float* r1 = y + 1 < y1 ? row(y + 1) : zeros;
    const float* r2 = y + 2 < y1 ? row(y + 2) : zeros;
    // Moments and the four lag products in one sweep over the whole row (whole vectors); the x
    // products that reach past the tile's last column (into the border, then the zero pad) are
    // taken off after.
    const RowSums r = row_sums_and_lags(r0, r1, r2, x0, x1);
    const float s = r.s, ss = r.ss, py1 = r.py1, py2 = r.py2;
    const float px1 = r.px1 - r0[x1 - 1] * r0[x1];
    const float px2 = w > 1 ? r.px2 - r0[x1 - 2] * r0[x1] : 0.0f;
    row_sums[y - y0] = s;
    t.n += w;
    t.sum += s;
    t.sumsq += ss;
    // Lags along x: pairs (x, x + 1) and (x, x + 2) inside the tile. The sums of either member
    // are the row sum without the end pixels.
    if (w > 1) {
      t.pairs[lag_x1] += w - 1;
      t.sum_xy[lag_x1] += px1;
      t.sum_x[lag_x1] += s - r0[x1 - 1];
      t.sum_y[lag_x1] += s - r0[x0];
    }
    if (w > 2) {
      t.pairs[lag_x2] += w - 2;
      t.sum_xy[lag_x2] += px2;
      t.sum_x[lag_x2] += s - r0[x1 - 1] - r0[x1 - 2];
      t.sum_y[lag_x2] += s - r0[x0] - r0[x0 + 1];
    }
    // Lags along y: rows y + 1 and y + 2 of the same tile (their sums are added below).
    if (y + 1 < y1) {
      t.pairs[lag_y1] += w;
      t.sum_xy[lag_y1] += py1;
      t.sum_x[lag_y1] += s;
    }
    if (y + 2 < y1) {
      t.pairs[lag_y2] += w;
      t.sum_xy[lag_y2] += py2;
      t.sum_x[lag_y2] += s;
    }

    // Tenengrad: Sobel gradient energy (the offset cancels in the differences).
    if (y >= 1 && y + 1 < g.height && sx1 > sx0) {
      const float* rm = row(y - 1);
      const float* rp = row(y + 1);
      const float energy = sobel_energy(rm, r0, rp, sx0, sx1);
      t.sobel += energy;
      t.sobel_n += sx1 - sx0;
    }
  }
  // The second member of a y pair is in row y + lag.
  for (int y = y0 + 1; y < y1; ++y) {
    t.sum_y[lag_y1] += row_sums[y - y0];
    if (y >= y0 + 2) t.sum_y[lag_y2] += row_sums[y - y0];
  }
}

template <typename T>
[[gnu::always_inline]] inline void detail_all(const Image& image, const TileGrid& g, const DetailLattice& lattice,
                                              DetailSums* sums, TileScratch& scratch) {
  for (int c = 0; c < lattice.count(); ++c)
    detail_tile<T>(image, g, lattice.tile_i(c % lattice.nx), lattice.tile_j(c / lattice.nx), sums[c], scratch);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void detail_all_u16(const Image& image, const TileGrid& g,
                                                                        const DetailLattice& lattice,
                                                                        DetailSums* sums, TileScratch& scratch) {
  detail_all<std::uint16_t>(image, g, lattice, sums, scratch);
}

[[gnu::target_clones("arch=x86-64-v3", "default")]] void detail_all_u8(const Image& image, const TileGrid& g,
                                                                       const DetailLattice& lattice, DetailSums* sums,
                                                                       TileScratch& scratch) {
  detail_all<std::uint8_t>(image, g, lattice, sums, scratch);
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

DetailLattice::DetailLattice(const TileGrid& grid, int max_tiles) : tiles_x(grid.nx), tiles_y(grid.ny) {
  const auto blocks = [&](int k) { return ((grid.nx + k - 1) / k) * ((grid.ny + k - 1) / k); };
  while (blocks(step) > max_tiles && step < std::max(grid.nx, grid.ny)) ++step;
  nx = (grid.nx + step - 1) / step;
  ny = (grid.ny + step - 1) / step;
}

void TileScratch::reserve(const TileGrid& grid) {
  const auto t = static_cast<std::size_t>(grid.tile);
  tile.resize((t + 3) * (t + 2));  // each is a no-op once sized
  row_sums.resize(t);
  zeros.assign(t + 2, 0.0f);
  const std::size_t per_row = t / kSampleStep + 1;
  sample.resize(per_row * per_row * static_cast<std::size_t>(grid.nx));
  band_samples.resize(static_cast<std::size_t>(grid.nx));
  band_saturated.resize(static_cast<std::size_t>(grid.nx));
  histogram.resize(2 * kTileBins);
  bin_index.resize(t / 2 + 1);
  rank_below.resize(kRankSelectMax);
  rank_at.resize(kRankSelectMax);
  maxima_rows.resize(3 * static_cast<std::size_t>(grid.width));
}

double DetailSums::variance() const {
  if (n <= 0) return 0.0;
  const double m = sum / n;
  return std::max(0.0, sumsq / n - m * m);
}

double DetailSums::covariance(int lag) const {
  const double p = pairs[lag];
  if (p <= 0 || n <= 0) return 0.0;
  const double m = sum / n;  // about the tile mean, in offset units like the sums
  return (sum_xy[lag] - m * (sum_x[lag] + sum_y[lag])) / p + m * m;
}

void scan_tiles(const Image& image, const TileGrid& grid, int full_scale, std::vector<std::uint32_t>& histogram,
                std::vector<TileLevel>& tiles, TileScratch& scratch) {
  if (image.type() == SampleType::u8)
    scan_all_u8(image, grid, full_scale, histogram.data(), tiles.data(), scratch);
  else
    scan_all_u16(image, grid, full_scale, histogram.data(), tiles.data(), scratch);
}

void measure_detail(const Image& image, const TileGrid& grid, const DetailLattice& lattice,
                    std::vector<DetailSums>& sums, TileScratch& scratch) {
  if (image.type() == SampleType::u8)
    detail_all_u8(image, grid, lattice, sums.data(), scratch);
  else
    detail_all_u16(image, grid, lattice, sums.data(), scratch);
}

std::uint64_t count_maxima(const Image& image, const TileGrid& grid, const std::vector<std::int32_t>& thresholds,
                           std::vector<std::uint32_t>& per_tile, TileScratch& scratch) {
  std::vector<std::uint16_t>& ring = scratch.maxima_rows;
  if (image.type() == SampleType::u8)
    return count_all_u8(image, grid, thresholds, per_tile, reinterpret_cast<std::uint8_t*>(ring.data()));
  return count_all_u16(image, grid, thresholds, per_tile, ring.data());
}

}  // namespace tomorig::quicklook::detail
