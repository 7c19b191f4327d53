// The spray quick-look (shadow_look.h): bright field, droplet shadows and LED pulse energies.
#include "tomorig/processing/quicklook/shadow_look.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

template <typename T>
float sample(const Image& image, int x, int y) {
  return static_cast<float>(image.row<T>(y)[x]);
}

float pixel(const Image& image, int x, int y) {
  return image.type() == SampleType::u16 ? sample<std::uint16_t>(image, x, y) : sample<std::uint8_t>(image, x, y);
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
  if (tile_px < 16 || tile_px > 512) throw bad_input(fmt::format("shadow quick-look: tile_px = {} must be in [16, 512]", tile_px));
  if (!(shadow_sigmas >= 1 && shadow_sigmas <= 50))
    throw bad_input(fmt::format("shadow quick-look: shadow_sigmas = {} must be in [1, 50]", shadow_sigmas));
  if (min_shadow_px < 1) throw bad_input(fmt::format("shadow quick-look: min_shadow_px = {} must be >= 1", min_shadow_px));
  if (reference_sets < 1)
    throw bad_input(fmt::format("shadow quick-look: reference_sets = {} must be >= 1", reference_sets));
  if (bit_depth != 0 && (bit_depth < 8 || bit_depth > 16))
    throw bad_input(fmt::format("shadow quick-look: bit_depth = {} must be 0 or 8..16", bit_depth));
  for (const auto& [name, t] : {std::pair{"energy_ratio", targets.energy_ratio},
                                std::pair{"shadow_coverage", targets.shadow_coverage},
                                std::pair{"uniformity", targets.uniformity}})
    if (const std::string problem = t.validate(fmt::format("shadow quick-look {}", name)); !problem.empty())
      throw bad_input(problem);
}

Flag ShadowFrame::overall() const {
  if (!std::isfinite(bright_level)) return Flag::red;
  return worst(uniformity.flag, shadow_coverage.flag);
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
  const int w = image.width(), h = image.height(), t = options_.tile_px;
  if (w < 16 || h < 16) throw bad_input(fmt::format("shadow quick-look: a {} x {} frame is too small (16 x 16 px at least)", w, h));
  const int bits = options_.bit_depth != 0 ? options_.bit_depth : image.type() == SampleType::u16 ? 16 : 8;
  const double full_scale = static_cast<double>((1u << bits) - 1u);
  out.width = w;
  out.height = h;
  const int tx = (w + t - 1) / t, ty = (h + t - 1) / t;
  for (TileMap* m : {&out.coverage_map, &out.level_map}) {
    m->tiles_x = tx;
    m->tiles_y = ty;
    m->tile_px = t;
    m->values.assign(static_cast<std::size_t>(tx) * ty, std::numeric_limits<float>::quiet_NaN());
  }

  // Local bright field: each tile's median (shadows are a minority of any tile), taken on
  // every other pixel of every other row (a quarter of the cost, the same median within the
  // noise), interpolated bilinearly between the tile centres (extrapolated linearly at the
  // borders) so that the LED's fall-off across a tile does not read as noise.
  const std::size_t n = static_cast<std::size_t>(w) * h;
  normalised_.resize(n);
  std::vector<float> levels;
  levels.reserve(static_cast<std::size_t>(tx) * ty);
  for (int j = 0; j < ty; ++j)
    for (int i = 0; i < tx; ++i) {
      tile_buffer_.clear();
      const int x1 = std::min(w, (i + 1) * t), y1 = std::min(h, (j + 1) * t);
      for (int y = j * t; y < y1; y += 2)
        for (int x = i * t; x < x1; x += 2) tile_buffer_.push_back(pixel(image, x, y));
      const double level = median_of(tile_buffer_);
      out.level_map.values[static_cast<std::size_t>(i + tx * j)] = static_cast<float>(level);
      if (level > 0) levels.push_back(static_cast<float>(level));
    }
  // Tile centres: (i + 0.5) t, except a partial last tile's, which is its own middle.
  const auto centre = [t](int i, int extent) { return 0.5 * (i * t + std::min(extent, (i + 1) * t)); };
  const auto bracket = [&](double p, int tiles, int extent, int& i0, float& f) {
    if (tiles < 2) {
      i0 = 0;
      f = 0;
      return;
    }
    i0 = std::clamp(static_cast<int>(std::floor(p / t - 0.5)), 0, tiles - 2);
    f = static_cast<float>((p - centre(i0, extent)) / (centre(i0 + 1, extent) - centre(i0, extent)));
  };
  column_tile_.resize(static_cast<std::size_t>(w));
  column_weight_.resize(static_cast<std::size_t>(w));
  for (int x = 0; x < w; ++x) bracket(x + 0.5, tx, w, column_tile_[static_cast<std::size_t>(x)], column_weight_[static_cast<std::size_t>(x)]);
  row_levels_.resize(static_cast<std::size_t>(tx));
  for (int y = 0; y < h; ++y) {
    int j0 = 0;
    float fy = 0;
    bracket(y + 0.5, ty, h, j0, fy);
    const int j1 = std::min(j0 + 1, ty - 1);
    for (int i = 0; i < tx; ++i)
      row_levels_[static_cast<std::size_t>(i)] = (1 - fy) * out.level_map.values[static_cast<std::size_t>(i + tx * j0)] +
                                                 fy * out.level_map.values[static_cast<std::size_t>(i + tx * j1)];
    float* row = normalised_.data() + static_cast<std::size_t>(y) * w;
    const auto normalise = [&](const auto* in) {
      for (int x = 0; x < w; ++x) {
        const int i0 = column_tile_[static_cast<std::size_t>(x)];
        const int i1 = std::min(i0 + 1, tx - 1);
        const float fx = column_weight_[static_cast<std::size_t>(x)];
        const float level = (1 - fx) * row_levels_[static_cast<std::size_t>(i0)] + fx * row_levels_[static_cast<std::size_t>(i1)];
        row[x] = level > 0 ? static_cast<float>(in[x]) / level : 1.0f;
      }
    };
    if (image.type() == SampleType::u16) normalise(image.row<std::uint16_t>(y));
    else normalise(image.row<std::uint8_t>(y));
  }
  if (levels.empty()) {
    // A dark frame: no bright field at all (the LED did not fire).
    out.bright_level = 0;
    out.bright_fraction = 0;
    out.noise = out.threshold = out.min_intensity = out.shadows_per_mpx = not_measured;
    out.uniformity.set(not_measured, options_.targets.uniformity);
    out.shadow_coverage.set(not_measured, options_.targets.shadow_coverage);
    out.shadows = 0;
    out.spray_tile_fraction = 0;
    return;
  }
  out.bright_level = percentile_of(levels, 0.5);
  out.bright_fraction = out.bright_level / full_scale;
  out.uniformity.set(percentile_of(levels, 0.05) / percentile_of(levels, 0.95), options_.targets.uniformity);

  // Noise of the normalised bright field: MAD about 1 on a strided sample (bounded cost).
  tile_buffer_.clear();
  const std::size_t stride = std::max<std::size_t>(1, n / 65536);
  for (std::size_t k = 0; k < n; k += stride) tile_buffer_.push_back(std::abs(normalised_[k] - 1.0f));
  out.noise = 1.4826 * median_of(tile_buffer_);
  out.threshold = 1.0 - options_.shadow_sigmas * std::max(out.noise, 1e-4);
  const float threshold = static_cast<float>(out.threshold);

  // Shadow pixels, grouped 8-connected by union-find over the frame.
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
  out.shadows = shadows;
  out.shadows_per_mpx = 1e6 * static_cast<double>(shadows) / static_cast<double>(n);
  out.min_intensity = deepest;
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
