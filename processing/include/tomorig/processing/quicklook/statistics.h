#pragma once
// Quick-look statistics of particle images at the acquisition rate (issue 16, item 1): what an
// operator needs within a second to judge seeding, illumination, focus and saturation.
//
// Per frame (Mono8 or Mono16/Mono12-in-16 Image): histogram and percentiles; saturated fraction
// and a per-tile saturation map; background level (global and per tile) and noise; particle
// image density ppp from local maxima above background + k sigma and from the autocovariance
// amplitude; particle image diameter d_tau from the autocovariance width; source density
// Ns = ppp (pi/4) d_tau^2; focus (noise-corrected, normalised Tenengrad) per tile. Per camera
// and double frame, also the A/B energy balance. Each figure is flagged green/amber/red
// against QuickLookTargets. docs/quicklook.md gives the definitions and the accuracy.
//
// How a pipeline stage calls this (one QuickLook per camera, kept for the whole run):
//
//   quicklook::QuickLook ql(options);       // once per camera; validates the options
//   quicklook::CameraQuickLook result;      // once per camera; reused, holds the maps
//   for each FrameSet set:                  // on the stage's thread
//     ql.analyse(set.cameras[c].a.image, set.cameras[c].b.image, result);
//     nlohmann::json j = result;            // quicklook/json.h, for the preview stream
//
// analyse() reads the images (views are fine: it never keeps them) and overwrites `result`.
// The QuickLook owns its work buffers (the full-resolution histogram, per-tile accumulators);
// they and the vectors in `result` are sized by the first frame and reused afterwards, so
// frames of an unchanged size allocate nothing. A QuickLook is not thread-safe: give each
// camera (or thread) its own. Analysing one exposure alone: analyse(image, frame_statistics).
// Cost: two passes over every pixel (histogram and tile backgrounds; local maxima), and the
// neighbourhood sums on a bounded sample of tiles (QuickLookOptions::detail_tiles), in loops
// the compiler vectorises (bench/quicklook_benchmark.cpp).
#include <cstdint>
#include <memory>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/quicklook/targets.h"

namespace tomorig::quicklook {

// Targets from the thesis (Sect. 2.3: 0.02-0.08 ppp, d_tau 2-3 px, Ns < 0.3) and the issue.
struct QuickLookTargets {
  Target ppp{0.02, 0.08, 0.25};
  Target diameter_px{2.0, 3.0, 0.25};
  Target source_density{0.0, 0.3, 0.25};
  Target saturated_fraction{0.0, 0.001, 9.0};  // < 0.1 % green, < 1 % amber
  Target energy_balance{0.9, 1.1, 0.25};       // mean excess intensity of B over that of A
  Target soft_tile_fraction{0.0, 0.1, 1.0};    // tiles whose focus is below half the median
};

struct QuickLookOptions {
  // Edge of the square tiles (px) of the maps, the local background and the focus figure.
  int tile_px = 64;
  // k: a local maximum counts as a particle image if it exceeds the local background by k
  // times the noise.
  double peak_sigmas = 5.0;
  // Bit depth of the data, which sets the saturation level 2^bits - 1 (12 for Mono12 in
  // 16-bit samples); 0: the sample type's (8 or 16).
  int bit_depth = 0;
  // The particle image diameter, the autocovariance ppp and the focus map need every pixel's
  // neighbours (lag products, Sobel), so they are measured on a sample of at most this many
  // tiles, one in every k x k block of tiles (k the smallest that fits), spread evenly over the
  // frame: their cost is bounded whatever the frame size. Frames of up to this many tiles
  // (1024 x 1024 px at 64 px tiles) are measured on every tile. The focus map has one value per
  // block. Histogram, saturation, background and local maxima always use every pixel.
  int detail_tiles = 256;
  // Bins of the display histogram, spread linearly over [0, full scale].
  int histogram_bins = 256;
  QuickLookTargets targets;

  // Throws tomorig::Error (bad_input) naming the field, its value and what is allowed.
  void validate() const;
};

// A coarse map over the tiles, row-major (tile (i, j) at values[i + tiles_x * j]). NaN where a
// tile has nothing to measure.
struct TileMap {
  int tiles_x = 0, tiles_y = 0, tile_px = 0;
  std::vector<float> values;
  float at(int i, int j) const { return values[static_cast<std::size_t>(i + tiles_x * j)]; }
};

// Percentiles of all pixels, counts.
struct Percentiles {
  double p1 = 0, p5 = 0, p50 = 0, p95 = 0, p99 = 0, p999 = 0;
};

struct FrameStatistics {
  int width = 0, height = 0;
  int full_scale = 0;  // saturation level, counts

  std::vector<std::uint32_t> histogram;  // options.histogram_bins bins over [0, full_scale]
  double histogram_bin_width = 0;        // counts per bin
  double mean = 0;                       // counts, all pixels
  double mean_excess = 0;                // mean above the local background: the particles' light
  Percentiles percentiles;

  // Background: the most probable level of pixels that hold no particle image (half-sample
  // mode of the histogram), its noise (1 sigma, counts), and the local background of the
  // tiles (the level particles are counted above) as percentiles over the tiles and a map.
  double background = 0;
  double noise = 0;
  double background_p5 = 0, background_p50 = 0, background_p95 = 0;
  TileMap background_map;

  Judged saturated_fraction;  // fraction of pixels at or above full_scale
  TileMap saturation_map;     // saturated fraction per tile

  // Particle images (docs/quicklook.md). Two estimates of the particle image density, each a
  // lower bound for its own reason: local maxima above the local background + k noise
  // undercount images that overlap; the autocovariance amplitude (Campbell's theorem: exact at
  // any density for equally bright images) reads low when brightness varies. ppp is the larger.
  double maxima_per_pixel = 0;
  double ppp_autocovariance = 0;  // NaN if not measurable
  Judged ppp;                     // particle images per pixel
  Judged diameter_px;             // d_tau: e^-2 diameter (4 sigma) of the Gaussian particle image,
                                  // from the autocovariance width, pixel integration removed
  Judged source_density;          // Ns = ppp (pi / 4) d_tau^2

  // Focus per tile (normalised Tenengrad): the Sobel gradient energy minus its noise part, over
  // 64 x the tile's variance minus the noise variance (px^-2). It depends on the particle image
  // shape only, not on brightness or density, and falls as the images blur. NaN for tiles
  // without particle signal. One value per block of k x k tiles (QuickLookOptions::
  // detail_tiles; tile_px is the block's edge), measured on the tile nearest the block's centre.
  TileMap focus_map;
  Judged soft_tile_fraction;  // tiles (with signal) whose focus is below half the median

  Flag overall() const;  // the worst flag of this frame
};

// One camera's double frame.
struct CameraQuickLook {
  FrameStatistics a, b;
  Judged energy_balance;  // B's mean excess intensity over A's (pulse energy balance)
  Flag overall() const;
};

class QuickLook {
 public:
  // Throws tomorig::Error (bad_input) for invalid options.
  explicit QuickLook(const QuickLookOptions& options = {});
  ~QuickLook();
  QuickLook(QuickLook&&) noexcept;
  QuickLook& operator=(QuickLook&&) noexcept;

  const QuickLookOptions& options() const { return options_; }

  // Statistics of one frame into `out` (its vectors are reused). Throws tomorig::Error
  // (bad_input) for an empty or float image, or one smaller than 8 x 8 pixels.
  void analyse(const Image& image, FrameStatistics& out);
  // Both exposures of a camera and their energy balance. A missing (empty) exposure is an
  // error: the stage decides what to report for incomplete sets.
  void analyse(const Image& a, const Image& b, CameraQuickLook& out);

 private:
  struct Work;
  QuickLookOptions options_;
  std::unique_ptr<Work> work_;
};

}  // namespace tomorig::quicklook
