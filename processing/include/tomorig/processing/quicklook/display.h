#pragma once
// Quick-look images for people: a raw frame or a volume projection stretched to 8 bits so the
// seeding, the spray or the light sheet can be judged at a glance in any image viewer.
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

}  // namespace tomorig::quicklook
