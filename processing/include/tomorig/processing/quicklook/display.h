#pragma once
// Quick-look images for people: a raw frame or a volume projection stretched to 8 bits so the
// seeding, the spray or the light sheet can be judged at a glance in any image viewer.
#include <cstdint>
#include <span>
#include <string>

#include "tomorig/core/image.h"
#include "tomorig/core/volume.h"

namespace tomorig::quicklook {

struct StretchOptions {
  // Samples at or below this percentile map to black, at or above `high_percentile` to white;
  // linear in between. Percentiles, not min/max, so a hot pixel or an empty border does not
  // wash the image out.
  double low_percentile = 1.0;
  double high_percentile = 99.9;

  // Throws tomorig::Error (bad_input) unless 0 <= low < high <= 100.
  void validate() const;
};

// An 8-bit copy of `image` (u8, u16 or f32) with a linear percentile stretch. An image whose
// percentiles coincide (e.g. all equal) comes out black. Non-finite samples count as 0.
Image stretch_to_8bit(const Image& image, const StretchOptions& options = {});

enum class Axis { x, y, z };

// Maximum-intensity projection along `axis` as a float image: along z it is nx wide and ny
// high (row j, column i), along y nx x nz, along x ny x nz. Zero where no voxel is active.
Image max_projection(const SparseVolume& volume, Axis axis);
Image max_projection(const DenseVolume& volume, Axis axis);

// A small 8-bit picture of a frame for the preview stream: `image` reduced by whole blocks to at
// most `max_side` pixels on its longer side, each block keeping its brightest pixel (so that
// particle images survive the reduction), then stretched as stretch_to_8bit does.
Image thumbnail(const Image& image, int max_side, const StretchOptions& options = {});

// A `width` x `height` 8-bit bar chart of histogram `counts` on a log scale (white bars on
// black; an empty bin leaves its column black). The last column is the last bin: with the
// quick-look's display histogram, the saturated pixels.
Image histogram_image(std::span<const std::uint32_t> counts, int width, int height);

// `image` (8-bit) with `lines` of text written under it in a black band, white, one line per
// entry; the picture is widened if a line needs more room. For snapshots with their numbers.
Image with_caption(const Image& image, std::span<const std::string> lines);

}  // namespace tomorig::quicklook
