#pragma once
// First stage of dot-grid detection: bright blobs in a (possibly inverted) target image, their
// sub-pixel centres, and the origin marker (a hollow square framing one dot).
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"

namespace tomorig::calibration::detail {

struct DotBlobs {
  std::vector<Vec2d> dots;         // sub-pixel centres (intensity-weighted centroids)
  std::optional<int> origin;       // index into `dots` of the dot framed by the marker
  int markers = 0;                 // hollow squares found (1 when all is well)
  std::vector<std::string> warnings;
};

// `white_dots` false inverts the image first. `max_feature_px` bounds the size of dots and
// marker (0: automatic). Never throws for an image without dots; the caller decides.
DotBlobs find_dot_blobs(const Image& image, bool white_dots, double max_feature_px);

}  // namespace tomorig::calibration::detail
