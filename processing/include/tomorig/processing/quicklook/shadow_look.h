#pragma once
// The spray quick-look (issue 20): what an operator of a shadowgraphy rig (inline pulsed LEDs,
// thesis Ch. 6-7) needs per set, where particle statistics mean nothing: the bright-field level
// and its uniformity, the droplet shadows (coverage, count, density, the deepest one), where
// the spray is in the view, and the LED pulse energies - pulse B against pulse A, and each
// against the run's own start - so that an LED losing 20 % of its energy is flagged at once.
//
//   quicklook::ShadowLook look(options);            // once per camera, kept for the run
//   quicklook::ShadowCameraLook result;             // reused
//   look.analyse(set.cameras[c].a.image, set.cameras[c].b.image, result);
//   nlohmann::json j = result;                      // quicklook/json.h
//
// Per frame: the frame is first binned b x b into a working image (the mean of each block), so
// that a full-size sCMOS frame (2560 x 2160 px of 6.5 um) is measured at the pixel size the
// reduced case is rendered at (26 um) and the stage keeps up with the rig (docs/spray.md). On
// the working image the local bright field is the median of each tile (droplet shadows cover a
// small part of a tile), the frame's level the median of the tiles'; intensities are divided by
// their tile's level (a flat field from the frame itself), the noise sigma of that normalised
// bright field is 1.4826 x its median absolute deviation, and a working pixel is in a shadow
// where it is below 1 - shadow_sigmas x sigma. Shadows are the 8-connected groups of such pixels
// of at least min_shadow_px working pixels. Buffers are sized by the first frame and reused.
// Not thread-safe.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/quicklook/statistics.h"
#include "tomorig/processing/quicklook/targets.h"

namespace tomorig::quicklook {

// The rig file's [quicklook.spray] keys override these (docs/configuration.md); these are
// their one default.
struct ShadowTargets {
  // Pulse energy: B's bright-field level over A's, and each pulse's level over the run's
  // reference. Green within 10 %; amber to 0.9 / 1.1 = 0.82; a 20 % drop (0.80) is red.
  Target energy_ratio{0.9, 1.1, 0.1};
  // Shadow coverage (fraction of pixels in a shadow): reconstruction, like ppp for particles,
  // needs sparse images. Green below 5 %, amber to 10 %.
  Target shadow_coverage{0.0, 0.05, 1.0};
  // Bright-field uniformity: the 5th over the 95th percentile of the tile levels.
  Target uniformity{0.7, 1.0, 0.25};
  // Bright-field level, fraction of full scale: far enough above the read noise that the
  // threshold of visibility (1 - 2 sigma) is set by shot noise, and clear of saturation, where
  // flat-fielding breaks. Green 2 % to 90 %; amber to 1.8 % and 99 %. (The thesis's LEDs gave
  // about 5 % of the 16-bit scale, Sect. 7.3.)
  Target bright_fraction{0.02, 0.9, 0.1};
  // What depends on the spray under study, so judged only when the rig sets it: the droplet
  // shadows per frame (amber 25 % beyond), and the deepest shadow's normalised intensity, whose
  // upper bound says large droplets are in view and in focus (amber 10 % above).
  std::optional<Target> shadow_count;
  std::optional<Target> min_intensity;
  static constexpr double shadow_count_amber = 0.25, min_intensity_amber = 0.1;
};

struct ShadowLookOptions {
  // Frame pixels binned b x b into a working pixel, 1..8; 0: automatic, the smallest b whose
  // working image has at most auto_working_px pixels (640 x 540 frames: 1; 2560 x 2160: 4).
  int binning = 0;
  static constexpr std::int64_t auto_working_px = 400'000;
  int tile_px = 64;             // tiles of the local bright field (working pixels), 16..512
  double shadow_sigmas = 4.0;   // a shadow pixel lies below 1 - k sigma of the bright field, k in [1, 50]
  int min_shadow_px = 2;        // smaller groups are noise, >= 1
  // Sets whose levels make the run's reference (their median), per exposure, >= 1.
  int reference_sets = 8;
  int bit_depth = 0;            // saturation level 2^bits - 1; 0: the sample type's
  ShadowTargets targets;
  void validate() const;        // bad_input naming the field
  // The binning a width x height frame is measured with (binning, or the automatic choice).
  int binning_for(int width, int height) const;
};

struct ShadowFrame {
  int width = 0, height = 0;               // the frame's, px
  int binning = 1;                         // frame pixels per working pixel, along x and y
  double bright_level = not_measured;      // counts per frame pixel: median of the tile medians
  Judged bright_fraction;                  // the level over full scale
  double noise = not_measured;             // sigma of the normalised bright field, frame pixels
  double working_noise = not_measured;     // the same on the working image (binning > 1: lower)
  double threshold = not_measured;         // normalised: 1 - shadow_sigmas x working_noise
  Judged uniformity;                       // p5 / p95 of the tile levels
  Judged shadow_coverage;                  // fraction of working pixels in a shadow
  Judged shadows;                          // droplet shadows (connected groups) in the frame
  double shadows_per_mpx = not_measured;   // shadow density, per 10^6 frame pixels
  Judged min_intensity;                    // the deepest normalised intensity of the working image
  double spray_tile_fraction = 0;          // tiles holding a shadow: how much of the view the spray fills
  TileMap coverage_map;                    // shadow coverage per tile (tile_px in frame pixels)
  TileMap level_map;                       // bright-field level per tile, counts
  Flag overall() const;
};

struct ShadowCameraLook {
  ShadowFrame a, b;
  Judged energy_ratio;          // B's bright-field level over A's
  Judged history_a, history_b;  // each pulse's level over the run's reference (its first sets)
  bool reference_ready = false; // the reference is fixed (history_* measured)
  // "LED pulse B 20 % below pulse A", "LED pulse A 21 % below the run's start", ...; empty: none.
  std::vector<std::string> alarms;
  Flag overall() const;
};

class ShadowLook {
 public:
  explicit ShadowLook(const ShadowLookOptions& options = {});  // bad_input for invalid options
  const ShadowLookOptions& options() const { return options_; }
  // One frame (u16 or u8). bad_input for an empty or float image or one under 16 x 16 px.
  void analyse(const Image& image, ShadowFrame& out);
  // A camera's double frame, its A/B energy ratio and the run history (this call's levels
  // join the reference while it is being collected).
  void analyse(const Image& a, const Image& b, ShadowCameraLook& out);

 private:
  ShadowLookOptions options_;
  std::vector<float> working_;          // the binned frame, counts per frame pixel
  std::vector<std::uint32_t> row_sums_; // binning: one band of b frame rows summed
  std::vector<float> normalised_;       // I / tile level
  std::vector<float> tile_buffer_;      // one tile's samples for the median
  struct Stencil {                      // the bright field at a position along one axis:
    int tile[3];                        // the tiles whose levels it weighs
    float weight[3];
  };
  std::vector<Stencil> columns_;        // per column of the working image
  std::vector<float> row_levels_;       // the bright field of the current row at the tile columns
  std::vector<std::int32_t> labels_;    // union-find parents of shadow pixels (-1: none)
  std::vector<std::uint32_t> sizes_;    // group sizes by root
  std::vector<double> reference_samples_[2];
  double reference_[2] = {not_measured, not_measured};
};

}  // namespace tomorig::quicklook
