// Quick-look statistics of one frame: the two tile passes (tile_pass.h) and the figures derived
// from their sums (histogram_stats.h, particle_model.h).
#include "tomorig/processing/quicklook/statistics.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "histogram_stats.h"
#include "particle_model.h"
#include "tile_pass.h"
#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

// Sobel's response: 8 x the gradient (kernel [1 2 1] x [-1 0 1]); to white noise of variance
// v: 12 v per axis.
constexpr double kSobelGain2 = 64.0;
constexpr double kSobelNoise = 24.0;
// Rounding to integer counts alone is noise of 1 / sqrt(12) counts.
const double kQuantisationNoise = 1.0 / std::sqrt(12.0);
constexpr int kMinSize = 8;
// Lag covariances count as particle signal beyond this many standard deviations of chance.
constexpr double kSignificance = 10.0;
// A frame whose lowest value holds more than this share of its pixels, at its mode, is clipped.
constexpr double kClippedFloorFraction = 0.05;

void check_target(const Target& t, std::string_view what) {
  if (const std::string problem = t.validate(what); !problem.empty()) throw bad_input(problem);
}

int full_scale_of(const Image& image, int bit_depth) {
  const int bits = bit_depth > 0 ? bit_depth : (image.type() == SampleType::u8 ? 8 : 16);
  if (image.type() == SampleType::u8 && bits > 8)
    throw bad_input(fmt::format("quick-look: bit depth {} does not fit an 8-bit (Mono8) image: use 8 or 0 (automatic)",
                                bits));
  return (1 << bits) - 1;
}

// `what`: "the frame", "frame A", ...
void check_image(const Image& image, const char* what) {
  if (image.empty()) throw bad_input(fmt::format("quick-look: {} is missing (empty image)", what));
  if (image.type() == SampleType::f32)
    throw bad_input(fmt::format("quick-look: {} holds float samples; quick-look reads camera frames (Mono8, Mono12 "
                                "or Mono16)",
                                what));
  if (image.width() < kMinSize || image.height() < kMinSize)
    throw bad_input(fmt::format("quick-look: {} is {} x {} px; at least {} x {} is needed", what, image.width(),
                                image.height(), kMinSize, kMinSize));
}

void resize_map(TileMap& map, const detail::TileGrid& g) {
  map.tiles_x = g.nx;
  map.tiles_y = g.ny;
  map.tile_px = g.tile;
  map.values.resize(static_cast<std::size_t>(g.count()));  // no allocation once sized
}

double median_of(std::vector<float>& scratch) {
  if (scratch.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = scratch.begin() + static_cast<std::ptrdiff_t>(scratch.size() / 2);
  std::nth_element(scratch.begin(), mid, scratch.end());
  return *mid;
}

double percentile_of(std::vector<float>& scratch, double p) {
  if (scratch.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto k = static_cast<std::ptrdiff_t>(std::lround(p * static_cast<double>(scratch.size() - 1)));
  std::nth_element(scratch.begin(), scratch.begin() + k, scratch.end());
  return scratch[static_cast<std::size_t>(k)];
}

}  // namespace

void QuickLookOptions::validate() const {
  if (tile_px < 16 || tile_px > 256)
    throw bad_input(fmt::format("quicklook.tile_px = {} is out of range: tiles are 16 to 256 px", tile_px));
  if (!(peak_sigmas >= 1.0 && peak_sigmas <= 50.0))
    throw bad_input(fmt::format("quicklook.peak_sigmas = {} is out of range: use 1 to 50 (default 5)", peak_sigmas));
  if (bit_depth != 0 && (bit_depth < 8 || bit_depth > 16))
    throw bad_input(fmt::format("quicklook.bit_depth = {} is out of range: 8 to 16, or 0 for the sample type's",
                                bit_depth));
  if (detail_tiles < 1 || detail_tiles > 65536)
    throw bad_input(fmt::format("quicklook.detail_tiles = {} is out of range: 1 to 65536 (default 256)", detail_tiles));
  if (histogram_bins < 2 || histogram_bins > 65536)
    throw bad_input(fmt::format("quicklook.histogram_bins = {} is out of range: 2 to 65536", histogram_bins));
  check_target(targets.ppp, "quicklook.ppp");
  check_target(targets.diameter_px, "quicklook.diameter_px");
  check_target(targets.source_density, "quicklook.source_density");
  check_target(targets.saturated_fraction, "quicklook.saturated_fraction");
  check_target(targets.energy_balance, "quicklook.energy_balance");
  check_target(targets.soft_tile_fraction, "quicklook.soft_tile_fraction");
}

Flag FrameStatistics::overall() const {
  Flag f = saturated_fraction.flag;
  for (const Judged* j : {&ppp, &diameter_px, &source_density, &soft_tile_fraction}) f = worst(f, j->flag);
  return f;
}

Flag CameraQuickLook::overall() const { return worst(worst(a.overall(), b.overall()), energy_balance.flag); }

// Work buffers, sized by the first frame and reused.
struct QuickLook::Work {
  detail::TileGrid grid;
  detail::DetailLattice lattice;
  std::vector<std::uint32_t> histogram;  // full resolution: one bin per value
  std::vector<detail::TileLevel> tiles;
  std::vector<detail::DetailSums> detail;  // per block of the lattice
  detail::TileScratch tile_scratch;
  std::vector<std::int32_t> thresholds;
  std::vector<std::uint32_t> maxima;
  std::vector<float> scratch;

  void prepare(const Image& image, int tile, int detail_tiles) {
    if (grid.width != image.width() || grid.height != image.height() || grid.tile != tile) {
      grid = detail::TileGrid(image.width(), image.height(), tile);
      lattice = detail::DetailLattice(grid, detail_tiles);
    }
    const std::size_t n = static_cast<std::size_t>(grid.count());
    tiles.resize(n);
    detail.resize(static_cast<std::size_t>(lattice.count()));
    thresholds.resize(n);
    maxima.resize(n);
    scratch.reserve(n);
    tile_scratch.reserve(grid);
    histogram.assign(2 * detail::kHistogramStride, 0u);
  }
};

QuickLook::QuickLook(const QuickLookOptions& options) : options_(options), work_(std::make_unique<Work>()) {
  options_.validate();
}
QuickLook::~QuickLook() = default;
QuickLook::QuickLook(QuickLook&&) noexcept = default;
QuickLook& QuickLook::operator=(QuickLook&&) noexcept = default;

void QuickLook::analyse(const Image& image, FrameStatistics& out) {
  check_image(image, "the frame");
  const int full_scale = full_scale_of(image, options_.bit_depth);
  Work& w = *work_;
  w.prepare(image, options_.tile_px, options_.detail_tiles);
  const detail::TileGrid& g = w.grid;
  const detail::DetailLattice& lattice = w.lattice;
  const QuickLookTargets& targets = options_.targets;

  // ---- Every pixel: histogram, saturation and each tile's background; the sample tiles:
  // moments, autocovariance and Sobel sums.
  detail::scan_tiles(image, g, full_scale, w.histogram, w.tiles, w.tile_scratch);
  detail::measure_detail(image, g, lattice, w.detail, w.tile_scratch);
  const double pixels = static_cast<double>(image.width()) * image.height();
  out.width = image.width();
  out.height = image.height();
  out.full_scale = full_scale;

  // ---- Histogram figures.
  const std::span<const std::uint32_t> hist =
      detail::histogram_halves(w.histogram, image.type() == SampleType::u8 ? 256u : 65536u);
  out.percentiles = {detail::quantile(hist, pixels, 0.01),  detail::quantile(hist, pixels, 0.05),
                     detail::quantile(hist, pixels, 0.50),  detail::quantile(hist, pixels, 0.95),
                     detail::quantile(hist, pixels, 0.99),  detail::quantile(hist, pixels, 0.999)};
  const int bins = options_.histogram_bins;
  out.histogram.assign(static_cast<std::size_t>(bins), 0u);
  out.histogram_bin_width = (full_scale + 1.0) / bins;
  for (std::size_t v = 0; v < hist.size(); ++v) {
    if (hist[v] == 0) continue;
    const auto bin = std::min<std::size_t>(static_cast<std::size_t>(bins - 1),
                                           static_cast<std::size_t>(static_cast<double>(v) / out.histogram_bin_width));
    out.histogram[bin] += hist[v];
  }

  // ---- Background and noise: each tile's (tile_pass.h), the frame's the median over tiles, so
  // that a gradient of stray light neither blurs the level nor passes for noise.
  w.scratch.clear();
  for (const detail::TileLevel& t : w.tiles) w.scratch.push_back(static_cast<float>(t.background));
  out.background = median_of(w.scratch);
  w.scratch.clear();
  for (const detail::TileLevel& t : w.tiles) w.scratch.push_back(static_cast<float>(t.noise));
  double noise = median_of(w.scratch);
  // A frame clipped at its lowest value (no black level) has no lower half to read the noise
  // from: the floor holds every negative excursion.
  const double floor = detail::quantile(hist, pixels, 0.0);
  const bool clipped = out.background - floor < 1.0 &&
                       hist[static_cast<std::size_t>(floor)] > kClippedFloorFraction * pixels;
  if (clipped) noise = detail::floor_clipped_sigma(hist, static_cast<int>(floor));

  // ---- Mean (from the histogram), saturation, autocovariance (the sample tiles').
  double sum = 0, saturated = 0, weight = 0;
  for (std::size_t v = 0; v < hist.size(); ++v) sum += static_cast<double>(v) * hist[v];
  for (const detail::TileLevel& t : w.tiles) saturated += t.saturated;
  double cov[detail::lag_count] = {};
  for (const detail::DetailSums& t : w.detail) {
    weight += t.n;
    for (int lag = 0; lag < detail::lag_count; ++lag) cov[lag] += t.n * t.covariance(lag);
  }
  out.mean = sum / pixels;
  out.saturated_fraction.set(saturated / pixels, targets.saturated_fraction);

  // d_tau from the ratio of lags 1 and 2, which white noise does not reach.
  const double c1 = 0.5 * (cov[detail::lag_x1] + cov[detail::lag_y1]) / weight;
  const double c2 = 0.5 * (cov[detail::lag_x2] + cov[detail::lag_y2]) / weight;
  out.noise = std::max(noise, kQuantisationNoise);
  // White noise alone leaves lag covariances of about noise^2 / sqrt(pixels) (either sign, the
  // pixels the covariances are measured on): both lags must stand well clear of that to say
  // anything about particle images.
  const double chance = kSignificance * out.noise * out.noise / std::sqrt(weight);
  const double sigma_px = c1 > chance && c2 > chance ? detail::sigma_from_lag_ratio(c1 / c2) : not_measured;
  out.diameter_px.set(4.0 * sigma_px, targets.diameter_px);

  // ---- Local background and thresholds.
  resize_map(out.background_map, g);
  resize_map(out.saturation_map, g);
  out.focus_map.tiles_x = lattice.nx;
  out.focus_map.tiles_y = lattice.ny;
  out.focus_map.tile_px = g.tile * lattice.step;
  out.focus_map.values.resize(static_cast<std::size_t>(lattice.count()));
  const double rise = options_.peak_sigmas * out.noise;
  w.scratch.clear();
  double background_sum = 0;
  for (std::size_t n = 0; n < w.tiles.size(); ++n) {
    const detail::TileLevel& t = w.tiles[n];
    const double local = clipped ? std::max(floor, t.background) : t.background;
    background_sum += local * t.pixels;
    out.background_map.values[n] = static_cast<float>(local);
    out.saturation_map.values[n] = static_cast<float>(t.saturated / t.pixels);
    w.thresholds[n] = static_cast<std::int32_t>(std::clamp(std::floor(local + rise), -1.0, 65536.0));
    w.scratch.push_back(static_cast<float>(local));
  }
  out.mean_excess = out.mean - background_sum / pixels;
  out.background_p5 = percentile_of(w.scratch, 0.05);
  out.background_p50 = percentile_of(w.scratch, 0.50);
  out.background_p95 = percentile_of(w.scratch, 0.95);

  // ---- Pass 2: particle images as local maxima.
  const std::uint64_t maxima = detail::count_maxima(image, g, w.thresholds, w.maxima, w.tile_scratch);
  const double interior = static_cast<double>(image.width() - 2) * (image.height() - 2);
  out.maxima_per_pixel = static_cast<double>(maxima) / interior;

  // ---- ppp: two lower bounds (particle_model.h), the larger kept. Overlapping images make
  // the maxima undercount; unequal brightness makes the autocovariance estimate low.
  out.ppp_autocovariance = detail::density_from_autocovariance(out.mean_excess, c1, sigma_px);
  const double ppp = std::isfinite(out.ppp_autocovariance) ? std::max(out.ppp_autocovariance, out.maxima_per_pixel)
                                                           : out.maxima_per_pixel;
  out.ppp.set(ppp, targets.ppp);
  out.source_density.set(ppp * std::numbers::pi / 4.0 * out.diameter_px.value * out.diameter_px.value,
                         targets.source_density);

  // ---- Focus per block of the lattice (its sample tile's), relative to the frame's median.
  const double noise_variance = out.noise * out.noise;
  w.scratch.clear();
  for (int c = 0; c < lattice.count(); ++c) {
    const detail::DetailSums& t = w.detail[static_cast<std::size_t>(c)];
    const double signal_variance = t.variance() - noise_variance;
    float focus = std::numeric_limits<float>::quiet_NaN();
    // A tile needs particle signal well above its noise to say anything about focus.
    if (t.sobel_n > 0 && signal_variance > noise_variance && w.maxima[lattice.tile_of(c)] > 0) {
      const double energy = t.sobel / t.sobel_n - kSobelNoise * noise_variance;
      focus = static_cast<float>(std::max(0.0, energy) / (kSobelGain2 * signal_variance));
      w.scratch.push_back(focus);
    }
    out.focus_map.values[static_cast<std::size_t>(c)] = focus;
  }
  const double median_focus = median_of(w.scratch);
  if (std::isfinite(median_focus) && median_focus > 0) {
    std::size_t soft = 0;
    for (const float f : w.scratch) soft += f < 0.5 * median_focus ? 1 : 0;
    out.soft_tile_fraction.set(static_cast<double>(soft) / static_cast<double>(w.scratch.size()),
                               targets.soft_tile_fraction);
  } else {
    out.soft_tile_fraction.set(not_measured, targets.soft_tile_fraction);
  }
}

void QuickLook::analyse(const Image& a, const Image& b, CameraQuickLook& out) {
  check_image(a, "frame A");
  check_image(b, "frame B");
  if (a.width() != b.width() || a.height() != b.height() || a.type() != b.type())
    throw bad_input(fmt::format("quick-look: frames A ({} x {} {}) and B ({} x {} {}) of a camera differ", a.width(),
                                a.height(), to_string(a.type()), b.width(), b.height(), to_string(b.type())));
  analyse(a, out.a);
  analyse(b, out.b);
  const double excess_a = out.a.mean_excess, excess_b = out.b.mean_excess;
  out.energy_balance.set(excess_a > 0 && excess_b >= 0 ? excess_b / excess_a : not_measured,
                         options_.targets.energy_balance);
}

}  // namespace tomorig::quicklook
