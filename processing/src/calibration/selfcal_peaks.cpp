#include "selfcal_peaks.h"

#include <algorithm>
#include <cmath>

namespace tomorig::calibration::selfcal {
namespace {

// Offset of the true maximum from the centre sample, in (-0.5, 0.5), from three samples.
double subpixel_offset(double left, double centre, double right) {
  if (left > 0 && centre > 0 && right > 0) {
    const double l = std::log(left), c = std::log(centre), r = std::log(right);
    const double denominator = 2.0 * (l - 2.0 * c + r);
    if (denominator < 0) return std::clamp((l - r) / denominator, -0.5, 0.5);
  }
  const double denominator = 2.0 * (left - 2.0 * centre + right);
  return denominator < 0 ? std::clamp((left - right) / denominator, -0.5, 0.5) : 0.0;
}

std::vector<float> to_float(const Image& image) {
  const int w = image.width(), h = image.height();
  std::vector<float> out(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int y = 0; y < h; ++y) {
    float* dst = out.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(w);
    switch (image.type()) {
      case SampleType::u8: std::copy_n(image.row<std::uint8_t>(y), w, dst); break;
      case SampleType::u16: std::copy_n(image.row<std::uint16_t>(y), w, dst); break;
      case SampleType::f32: std::copy_n(image.row<float>(y), w, dst); break;
    }
  }
  return out;
}

double automatic_threshold(const std::vector<float>& pixels) {
  std::vector<float> sorted(pixels);
  const std::size_t k = std::min(sorted.size() - 1, static_cast<std::size_t>(0.999 * static_cast<double>(sorted.size())));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  return 0.1 * sorted[k];
}

}  // namespace

std::vector<Vec2d> detect_peaks(const Image& image, double threshold) {
  std::vector<Vec2d> peaks;
  const int w = image.width(), h = image.height();
  if (w < 3 || h < 3) return peaks;
  const std::vector<float> v = to_float(image);
  if (threshold <= 0) threshold = automatic_threshold(v);
  if (!(threshold > 0)) return peaks;  // a blank image
  const auto at = [&](int x, int y) { return v[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)]; };
  for (int y = 1; y < h - 1; ++y)
    for (int x = 1; x < w - 1; ++x) {
      const float c = at(x, y);
      if (c < threshold) continue;
      // Strictly above the neighbours before it, at least equal to those after it: a flat
      // top of two equal pixels gives one peak, not two.
      if (!(c > at(x - 1, y - 1) && c > at(x, y - 1) && c > at(x + 1, y - 1) && c > at(x - 1, y) &&
            c >= at(x + 1, y) && c >= at(x - 1, y + 1) && c >= at(x, y + 1) && c >= at(x + 1, y + 1)))
        continue;
      peaks.push_back({x + subpixel_offset(at(x - 1, y), c, at(x + 1, y)),
                       y + subpixel_offset(at(x, y - 1), c, at(x, y + 1))});
    }
  return peaks;
}

PeakIndex::PeakIndex(std::vector<Vec2d> peaks, int width, int height, double cell_px)
    : peaks_(std::move(peaks)),
      cell_(cell_px),
      nx_(std::max(1, static_cast<int>(std::ceil((width + 1) / cell_px)))),
      ny_(std::max(1, static_cast<int>(std::ceil((height + 1) / cell_px)))) {
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  start_.assign(cells + 1, 0);
  std::vector<int> cell_index(peaks_.size());
  for (std::size_t n = 0; n < peaks_.size(); ++n) {
    cell_index[n] = cell_of(peaks_[n].x, nx_) + nx_ * cell_of(peaks_[n].y, ny_);
    ++start_[static_cast<std::size_t>(cell_index[n]) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  order_.resize(peaks_.size());
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t n = 0; n < peaks_.size(); ++n) order_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_index[n])]++)] = static_cast<int>(n);
}

int PeakIndex::cell_of(double coordinate, int cells) const {
  // Pixel coordinates start at -0.5; clamp so that points off the image use the edge cells.
  const double c = std::floor((coordinate + 0.5) / cell_);
  return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(cells - 1)));
}

int PeakIndex::nearest(const Vec2d& p, double radius) const {
  int best = -1;
  double best_d2 = radius * radius;
  for_each_in_box(p.x - radius, p.y - radius, p.x + radius, p.y + radius, [&](int n) {
    const double dx = peaks_[static_cast<std::size_t>(n)].x - p.x, dy = peaks_[static_cast<std::size_t>(n)].y - p.y;
    const double d2 = dx * dx + dy * dy;
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = n;
    }
  });
  return best;
}

}  // namespace tomorig::calibration::selfcal
