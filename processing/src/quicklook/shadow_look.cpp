// The spray quick-look (shadow_look.h): bright field, droplet shadows and LED pulse energies.
#include "tomorig/processing/quicklook/shadow_look.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

// The frame binned b x b into `out` (wb x hb, the mean of each block, counts per frame pixel):
// b rows summed column by column (a loop the compiler vectorises), then b columns at a time.
// A partial last block (w or h not a multiple of b) is left out.
template <typename T>
void bin_frame(const Image& image, int b, std::vector<std::uint32_t>& sums, std::vector<float>& out) {
  const int wb = image.width() / b, hb = image.height() / b, w = wb * b;
  out.resize(static_cast<std::size_t>(wb) * hb);
  sums.resize(static_cast<std::size_t>(w));
  const float scale = 1.0f / static_cast<float>(b * b);
  for (int yb = 0; yb < hb; ++yb) {
    std::uint32_t* acc = sums.data();
    const T* first = image.row<T>(yb * b);
    for (int x = 0; x < w; ++x) acc[x] = first[x];
    for (int r = 1; r < b; ++r) {
      const T* in = image.row<T>(yb * b + r);
      for (int x = 0; x < w; ++x) acc[x] += in[x];
    }
    float* row = out.data() + static_cast<std::size_t>(yb) * wb;
    for (int xb = 0; xb < wb; ++xb) {
      std::uint32_t sum = 0;
      for (int k = 0; k < b; ++k) sum += acc[xb * b + k];
      row[xb] = static_cast<float>(sum) * scale;
    }
  }
}

template <typename T>
void copy_frame(const Image& image, std::vector<float>& out) {
  const int w = image.width(), h = image.height();
  out.resize(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const T* in = image.row<T>(y);
    float* row = out.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) row[x] = static_cast<float>(in[x]);
  }
}

// A figure judged against a target the rig may leave unset: then it is reported, green.
void judge_optional(Judged& out, double value, const std::optional<Target>& target) {
  if (target) {
    out.set(value, *target);
  } else {
    out.value = value;
    out.flag = Flag::green;
  }
}

// The median of `v` (reordered).
double median_of(std::vector<float>& v) {
  if (v.empty()) return not_measured;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double percentile_of(std::vector<float> v, double q) {
  if (v.empty()) return not_measured;
  const auto k = v.begin() + static_cast<std::ptrdiff_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), k, v.end());
  return *k;
}

std::int32_t find_root(std::vector<std::int32_t>& parent, std::int32_t i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

void unite(std::vector<std::int32_t>& parent, std::int32_t a, std::int32_t b) {
  a = find_root(parent, a);
  b = find_root(parent, b);
  if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
}

std::string percent_below(double ratio) { return fmt::format("{:.0f} %", 100.0 * (1.0 - ratio)); }

}  // namespace

void ShadowLookOptions::validate() const {
  if (binning < 0 || binning > 8)
    throw bad_input(fmt::format("shadow quick-look: binning = {} must be 0 (automatic) or 1 to 8", binning));
  if (tile_px < 16 || tile_px > 512) throw bad_input(fmt::format("shadow quick-look: tile_px = {} must be in [16, 512]", tile_px));
  if (!(shadow_sigmas >= 1 && shadow_sigmas <= 50))
    throw bad_input(fmt::format("shadow quick-look: shadow_sigmas = {} must be in [1, 50]", shadow_sigmas));
  if (min_shadow_px < 1) throw bad_input(fmt::format("shadow quick-look: min_shadow_px = {} must be >= 1", min_shadow_px));
  if (reference_sets < 1)
    throw bad_input(fmt::format("shadow quick-look: reference_sets = {} must be >= 1", reference_sets));
  if (bit_depth != 0 && (bit_depth < 8 || bit_depth > 16))
    throw bad_input(fmt::format("shadow quick-look: bit_depth = {} must be 0 or 8..16", bit_depth));
  const Target unset{0.0, 1.0, 0.0};  // stands in for an optional target left out
  for (const auto& [name, t] : {std::pair{"energy_ratio", targets.energy_ratio},
                                std::pair{"shadow_coverage", targets.shadow_coverage},
                                std::pair{"uniformity", targets.uniformity},
                                std::pair{"bright_fraction", targets.bright_fraction},
                                std::pair{"shadow_count", targets.shadow_count.value_or(unset)},
                                std::pair{"min_intensity", targets.min_intensity.value_or(unset)}})
    if (const std::string problem = t.validate(fmt::format("shadow quick-look {}", name)); !problem.empty())
      throw bad_input(problem);
  // Fractions of the frame or of the bright field: above 1 they could never be reached.
  if (targets.shadow_coverage.high > 1 || targets.uniformity.low > 1 || targets.bright_fraction.low > 1)
    throw bad_input(fmt::format("shadow quick-look: coverage high {}, uniformity low {} and bright_fraction low {} "
                                "must be at most 1",
                                targets.shadow_coverage.high, targets.uniformity.low, targets.bright_fraction.low));
}

int ShadowLookOptions::binning_for(int width, int height) const {
  if (binning > 0) return binning;
  const std::int64_t pixels = static_cast<std::int64_t>(width) * height;
  int b = 1;
  while (b < 8 && pixels > auto_working_px * b * b) ++b;
  return b;
}

Flag ShadowFrame::overall() const {
  if (!std::isfinite(bright_level)) return Flag::red;
  return worst(worst(worst(uniformity.flag, shadow_coverage.flag), worst(bright_fraction.flag, shadows.flag)),
               min_intensity.flag);
}

Flag ShadowCameraLook::overall() const {
  Flag f = worst(worst(a.overall(), b.overall()), energy_ratio.flag);
  if (reference_ready) f = worst(f, worst(history_a.flag, history_b.flag));
  return f;
}

ShadowLook::ShadowLook(const ShadowLookOptions& options) : options_(options) { options_.validate(); }

void ShadowLook::analyse(const Image& image, ShadowFrame& out) {
  if (image.empty()) throw bad_input("shadow quick-look: the frame is empty");
  if (image.type() != SampleType::u16 && image.type() != SampleType::u8)
    throw bad_input("shadow quick-look: the frame must hold 8- or 16-bit samples");
  const int fw = image.width(), fh = image.height(), t = options_.tile_px;
  if (fw < 16 || fh < 16)
    throw bad_input(fmt::format("shadow quick-look: a {} x {} frame is too small (16 x 16 px at least)", fw, fh));
  const int bits = options_.bit_depth != 0 ? options_.bit_depth : image.type() == SampleType::u16 ? 16 : 8;
  const double full_scale = static_cast<double>((1u << bits) - 1u);
  // A frame too small for the binning is measured at a coarser working size no further than 8 px.
  const int b = std::max(1, std::min(options_.binning_for(fw, fh), std::min(fw, fh) / 8));
  out.width = fw;
  out.height = fh;
  out.binning = b;
  const bool wide = image.type() == SampleType::u16;
  if (b == 1) {
    if (wide) copy_frame<std::uint16_t>(image, working_);
    else copy_frame<std::uint8_t>(image, working_);
  } else {
    if (wide) bin_frame<std::uint16_t>(image, b, row_sums_, working_);
    else bin_frame<std::uint8_t>(image, b, row_sums_, working_);
  }
  const int w = fw / b, h = fh / b;
  const int tx = (w + t - 1) / t, ty = (h + t - 1) / t;
  for (TileMap* m : {&out.coverage_map, &out.level_map}) {
    m->tiles_x = tx;
    m->tiles_y = ty;
    m->tile_px = t * b;
    m->values.assign(static_cast<std::size_t>(tx) * ty, std::numeric_limits<float>::quiet_NaN());
  }
  const auto at = [&](int x, int y) { return working_[static_cast<std::size_t>(y) * w + x]; };

  // Local bright field: each tile's median (shadows are a minority of any tile), taken on
  // every other pixel of every other row (a quarter of the cost, the same median within the
  // noise), interpolated between the tile centres (stencil below) so that the LED's fall-off
  // across a tile does not read as noise.
  const std::size_t n = static_cast<std::size_t>(w) * h;
  normalised_.resize(n);
  std::vector<float> levels;
  levels.reserve(static_cast<std::size_t>(tx) * ty);
  for (int j = 0; j < ty; ++j)
    for (int i = 0; i < tx; ++i) {
      tile_buffer_.clear();
      const int x1 = std::min(w, (i + 1) * t), y1 = std::min(h, (j + 1) * t);
      for (int y = j * t; y < y1; y += 2)
        for (int x = i * t; x < x1; x += 2) tile_buffer_.push_back(at(x, y));
      const double level = median_of(tile_buffer_);
      out.level_map.values[static_cast<std::size_t>(i + tx * j)] = static_cast<float>(level);
      if (level > 0) levels.push_back(static_cast<float>(level));
    }
  // Tile centres: (i + 0.5) t, except a partial last tile's, which is its own middle.
  const auto centre = [t](int i, int extent) { return 0.5 * (i * t + std::min(extent, (i + 1) * t)); };
  // Along one axis: linear between the two tile centres around p; beyond the outer centres,
  // quadratic through the three outer ones (linear with two tiles, constant with one). A linear
  // extrapolation of the LED's concave fall-off overshoots it towards the border by ~0.2 % of
  // the level, which on a binned image (noise ~0.15 %) reads as shadow.
  const auto stencil = [&](double p, int tiles, int extent) {
    Stencil s{{0, 0, 0}, {1, 0, 0}};
    if (tiles < 2) return s;
    if (tiles >= 3 && (p < centre(0, extent) || p > centre(tiles - 1, extent))) {
      const int i0 = p < centre(0, extent) ? 0 : tiles - 3;
      for (int k = 0; k < 3; ++k) {
        double weight = 1;
        for (int m = 0; m < 3; ++m)
          if (m != k)
            weight *= (p - centre(i0 + m, extent)) / (centre(i0 + k, extent) - centre(i0 + m, extent));
        s.tile[k] = i0 + k;
        s.weight[k] = static_cast<float>(weight);
      }
      return s;
    }
    const int i0 = std::clamp(static_cast<int>(std::floor(p / t - 0.5)), 0, tiles - 2);
    const double f = (p - centre(i0, extent)) / (centre(i0 + 1, extent) - centre(i0, extent));
    s.tile[0] = i0;
    s.tile[1] = s.tile[2] = i0 + 1;
    s.weight[0] = static_cast<float>(1 - f);
    s.weight[1] = static_cast<float>(f);
    s.weight[2] = 0;
    return s;
  };
  const auto tile_level = [&](int i, int j) { return out.level_map.values[static_cast<std::size_t>(i + tx * j)]; };
  columns_.resize(static_cast<std::size_t>(w));
  for (int x = 0; x < w; ++x) columns_[static_cast<std::size_t>(x)] = stencil(x + 0.5, tx, w);
  row_levels_.resize(static_cast<std::size_t>(tx));
  for (int y = 0; y < h; ++y) {
    const Stencil sy = stencil(y + 0.5, ty, h);
    for (int i = 0; i < tx; ++i)
      row_levels_[static_cast<std::size_t>(i)] = sy.weight[0] * tile_level(i, sy.tile[0]) +
                                                 sy.weight[1] * tile_level(i, sy.tile[1]) +
                                                 sy.weight[2] * tile_level(i, sy.tile[2]);
    float* row = normalised_.data() + static_cast<std::size_t>(y) * w;
    const float* in = working_.data() + static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      const Stencil& sx = columns_[static_cast<std::size_t>(x)];
      const float level = sx.weight[0] * row_levels_[static_cast<std::size_t>(sx.tile[0])] +
                          sx.weight[1] * row_levels_[static_cast<std::size_t>(sx.tile[1])] +
                          sx.weight[2] * row_levels_[static_cast<std::size_t>(sx.tile[2])];
      row[x] = level > 0 ? in[x] / level : 1.0f;
    }
  }
  if (levels.empty()) {
    // A dark frame: no bright field at all (the LED did not fire).
    out.bright_level = 0;
    out.bright_fraction.set(0, options_.targets.bright_fraction);
    out.noise = out.working_noise = out.threshold = out.shadows_per_mpx = not_measured;
    out.uniformity.set(not_measured, options_.targets.uniformity);
    out.shadow_coverage.set(not_measured, options_.targets.shadow_coverage);
    judge_optional(out.shadows, 0, options_.targets.shadow_count);
    judge_optional(out.min_intensity, not_measured, options_.targets.min_intensity);
    out.spray_tile_fraction = 0;
    return;
  }
  out.bright_level = percentile_of(levels, 0.5);
  out.bright_fraction.set(out.bright_level / full_scale, options_.targets.bright_fraction);
  out.uniformity.set(percentile_of(levels, 0.05) / percentile_of(levels, 0.95), options_.targets.uniformity);

  // Noise of the normalised bright field on a strided sample (bounded cost): 1.4826 x the
  // median absolute difference of horizontal neighbours over sqrt 2. Differences, not deviations
  // from 1: the flat field interpolated between tile levels is off by up to ~0.2 % where the
  // LED's fall-off curves (mid-tile, the corners), which is nothing against a frame pixel's
  // noise but more than a binned one's. Taken on the working image (it sets the threshold) and,
  // when binned, on the frame's own pixels (what the threshold of visibility, 1 - 2 sigma, is
  // about; neighbours share their level).
  constexpr std::size_t samples = 65536;
  constexpr double mad_to_sigma = 1.4826 / 1.4142135623730951;
  tile_buffer_.clear();
  const std::size_t stride = std::max<std::size_t>(1, n / samples) | 1;  // odd: not locked to a column
  for (std::size_t k = 0; k + 1 < n; k += stride)
    if ((k + 1) % static_cast<std::size_t>(w) != 0) tile_buffer_.push_back(std::abs(normalised_[k + 1] - normalised_[k]));
  out.working_noise = mad_to_sigma * median_of(tile_buffer_);
  out.noise = out.working_noise;
  if (b > 1) {
    // Whole rows at a stride, read in order: a sample scattered over the frame would miss the
    // cache at every pixel, which cost more than binning the frame.
    tile_buffer_.clear();
    const int fwb = w * b, fhb = h * b;
    const int rows = std::max(1, static_cast<int>(samples / static_cast<std::size_t>(fwb - 1)));
    const int row_stride = std::max(1, fhb / rows);
    const auto sample_rows = [&](const auto* type_tag) {
      using T = std::remove_const_t<std::remove_pointer_t<decltype(type_tag)>>;
      for (int y = row_stride / 2; y < fhb; y += row_stride) {
        const T* in = image.row<T>(y);
        const float* norm = normalised_.data() + static_cast<std::size_t>(y / b) * w;
        const float* work = working_.data() + static_cast<std::size_t>(y / b) * w;
        for (int x = 0; x + 1 < fwb; ++x) {
          // The bright field of the working pixel holding (x, y): its value over its normalised one.
          const int xb = x / b;
          if (!(norm[xb] > 0 && work[xb] > 0)) continue;
          const float level = work[xb] / norm[xb];
          tile_buffer_.push_back(std::abs(static_cast<float>(in[x + 1]) - static_cast<float>(in[x])) / level);
        }
      }
    };
    if (wide) sample_rows(static_cast<const std::uint16_t*>(nullptr));
    else sample_rows(static_cast<const std::uint8_t*>(nullptr));
    out.noise = mad_to_sigma * median_of(tile_buffer_);
  }
  out.threshold = 1.0 - options_.shadow_sigmas * std::max(out.working_noise, 1e-4);
  const float threshold = static_cast<float>(out.threshold);

  // Shadow pixels, grouped 8-connected by union-find over the working image.
  labels_.assign(n, -1);
  float deepest = 1.0f;
  std::uint64_t shadow_pixels = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * w + x;
      const float v = normalised_[k];
      deepest = std::min(deepest, v);
      if (v >= threshold) continue;
      ++shadow_pixels;
      const auto self = static_cast<std::int32_t>(k);
      labels_[k] = self;
      if (x > 0 && labels_[k - 1] >= 0) unite(labels_, self, labels_[k - 1]);
      if (y > 0) {
        const std::size_t up = k - static_cast<std::size_t>(w);
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || x + dx >= w) continue;
          const std::int32_t l = labels_[up + static_cast<std::size_t>(dx)];
          if (l >= 0) unite(labels_, self, l);
        }
      }
    }
  sizes_.assign(n, 0);
  std::vector<std::uint32_t> tile_shadow(static_cast<std::size_t>(tx) * ty, 0), tile_pixels(tile_shadow.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t k = static_cast<std::size_t>(y) * w + x;
      const std::size_t tile = static_cast<std::size_t>(x / t + tx * (y / t));
      ++tile_pixels[tile];
      if (labels_[k] < 0) continue;
      ++tile_shadow[tile];
      ++sizes_[static_cast<std::size_t>(find_root(labels_, static_cast<std::int32_t>(k)))];
    }
  std::uint64_t shadows = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (sizes_[k] >= static_cast<std::uint32_t>(options_.min_shadow_px)) ++shadows;
  std::size_t spray_tiles = 0;
  for (std::size_t k = 0; k < tile_shadow.size(); ++k) {
    out.coverage_map.values[k] = static_cast<float>(tile_shadow[k]) / static_cast<float>(tile_pixels[k]);
    if (tile_shadow[k] >= static_cast<std::uint32_t>(options_.min_shadow_px)) ++spray_tiles;
  }
  judge_optional(out.shadows, static_cast<double>(shadows), options_.targets.shadow_count);
  out.shadows_per_mpx = 1e6 * static_cast<double>(shadows) / (static_cast<double>(fw) * fh);
  judge_optional(out.min_intensity, deepest, options_.targets.min_intensity);
  out.spray_tile_fraction = static_cast<double>(spray_tiles) / static_cast<double>(tile_shadow.size());
  out.shadow_coverage.set(static_cast<double>(shadow_pixels) / static_cast<double>(n), options_.targets.shadow_coverage);
}

void ShadowLook::analyse(const Image& a, const Image& b, ShadowCameraLook& out) {
  analyse(a, out.a);
  analyse(b, out.b);
  out.alarms.clear();
  const Target& energy = options_.targets.energy_ratio;
  out.energy_ratio.set(out.a.bright_level > 0 ? out.b.bright_level / out.a.bright_level : not_measured, energy);
  if (out.energy_ratio.flag == Flag::red)
    out.alarms.push_back(std::isfinite(out.energy_ratio.value) && out.energy_ratio.value < 1
                             ? fmt::format("LED pulse B {} below pulse A", percent_below(out.energy_ratio.value))
                         : std::isfinite(out.energy_ratio.value)
                             ? fmt::format("LED pulse B {:.0f} % above pulse A", 100.0 * (out.energy_ratio.value - 1.0))
                             : std::string("LED pulse A gave no bright field"));

  // The run's reference: the median level of each pulse over its first sets.
  const double levels[2] = {out.a.bright_level, out.b.bright_level};
  Judged* history[2] = {&out.history_a, &out.history_b};
  out.reference_ready = true;
  for (int e = 0; e < 2; ++e) {
    if (!std::isfinite(reference_[e]) && levels[e] > 0) {
      reference_samples_[e].push_back(levels[e]);
      if (reference_samples_[e].size() >= static_cast<std::size_t>(options_.reference_sets)) {
        std::vector<float> v(reference_samples_[e].begin(), reference_samples_[e].end());
        reference_[e] = percentile_of(v, 0.5);
      }
    }
    if (!std::isfinite(reference_[e])) {
      out.reference_ready = false;
      history[e]->set(not_measured, energy);
      history[e]->flag = Flag::green;  // not judged while the reference is being collected
      continue;
    }
    history[e]->set(levels[e] / reference_[e], energy);
    if (history[e]->flag == Flag::red && history[e]->value < 1)
      out.alarms.push_back(fmt::format("LED pulse {} {} below the run's start", e == 0 ? 'A' : 'B',
                                       percent_below(history[e]->value)));
  }
}

}  // namespace tomorig::quicklook
