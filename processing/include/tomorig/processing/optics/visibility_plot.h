#pragma once
// The Fig. 6.16 / 7.10-style plot of a visibility table: smallest visible droplet diameter over
// depth, one marked grey curve per camera and the set-up's limit (the largest) as a thick black
// line. An 8-bit grey image, for storage::write_png.
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/optics/visibility.h"

namespace tomorig::optics {

// Throws bad_input if `rows` is empty.
Image visibility_plot(const VisibilitySetup& setup, const std::vector<VisibilityRow>& rows);

}  // namespace tomorig::optics
