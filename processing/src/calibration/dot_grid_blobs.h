#pragma once
// First stage of dot-grid detection: bright blobs in a (possibly inverted) target image, their
// sub-pixel centres, and the markers: a hollow square framing the origin dot, a filled square
// in place of the origin dot, filled triangles in place of dots on the +x axis.
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"

namespace tomorig::calibration::detail {

enum class MarkerShape { hollow_square, filled_square, triangle };

struct FoundMarker {
  MarkerShape shape = MarkerShape::hollow_square;
  Vec2d centre;         // hollow: the framed dot's centre; filled: the shape's centroid
  int framed_dot = -1;  // hollow: index into `dots` of the framed dot
};

struct DotBlobs {
  std::vector<Vec2d> dots;  // sub-pixel centres (intensity-weighted centroids)
  std::vector<FoundMarker> markers;
  std::vector<std::string> warnings;
};

// `white_dots` false inverts the image first. `max_feature_px` bounds the size of dots and
// marker (0: automatic). Never throws for an image without dots; the caller decides.
DotBlobs find_dot_blobs(const Image& image, bool white_dots, double max_feature_px);

}  // namespace tomorig::calibration::detail
