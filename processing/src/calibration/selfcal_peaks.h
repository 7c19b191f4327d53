#pragma once
// Particle peaks of one image for volume self-calibration, and a spatial index over them.
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"

namespace tomorig::calibration::selfcal {

// Local maxima above `threshold` (counts; 0: 10 % of the image's 99.9th percentile), located
// to sub-pixel precision by a 3-point Gaussian fit along each axis (a parabola where a
// neighbour is not positive). Border pixels are skipped: the fit needs both neighbours.
std::vector<Vec2d> detect_peaks(const Image& image, double threshold);

// Peaks bucketed in square cells, so that the peaks near a point or a segment are found
// without a scan of the whole image.
class PeakIndex {
 public:
  PeakIndex(std::vector<Vec2d> peaks, int width, int height, double cell_px = 4.0);

  const std::vector<Vec2d>& peaks() const { return peaks_; }
  // Calls f(index) for each peak in cells touching the box [x0, x1] x [y0, y1] (a superset of
  // the peaks inside the box; callers test the distance they need).
  template <typename F>
  void for_each_in_box(double x0, double y0, double x1, double y1, F&& f) const {
    const int cx0 = cell_of(x0, nx_), cx1 = cell_of(x1, nx_);
    const int cy0 = cell_of(y0, ny_), cy1 = cell_of(y1, ny_);
    for (int cy = cy0; cy <= cy1; ++cy)
      for (int cx = cx0; cx <= cx1; ++cx) {
        const int c = cx + nx_ * cy;
        for (int n = start_[c]; n < start_[c + 1]; ++n) f(order_[n]);
      }
  }
  // The nearest peak within `radius` of p, or -1.
  int nearest(const Vec2d& p, double radius) const;

 private:
  int cell_of(double coordinate, int cells) const;

  std::vector<Vec2d> peaks_;
  double cell_;
  int nx_, ny_;
  std::vector<int> start_;  // CSR: peaks of cell c are order_[start_[c] .. start_[c + 1])
  std::vector<int> order_;
};

}  // namespace tomorig::calibration::selfcal
