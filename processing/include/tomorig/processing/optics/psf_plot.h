#pragma once
// The Fig. 6.15 / 7.9-style plot of a PSF table: each camera's PSF half-width over depth, the
// camera's own (chi_um, marked line) and as measured in the voxel planes (chi_voxel_um, thin
// line). An 8-bit grey image, for storage::write_png.
#include "tomorig/core/image.h"
#include "tomorig/processing/optics/psf_table.h"

namespace tomorig::optics {

// Throws bad_input if the table has no cameras.
Image psf_plot(const PsfTable& table);

}  // namespace tomorig::optics
