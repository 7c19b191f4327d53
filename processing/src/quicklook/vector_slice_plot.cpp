#include "tomorig/processing/quicklook/vector_slice_plot.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

constexpr int kLeft = 70, kTop = 40, kBottom = 90, kBarGap = 30, kBarWidth = 20, kBarLabels = 80;
constexpr int kInvalidGrey = 0, kLowestGrey = 50;  // a valid node is never as dark as an invalid one

void text(cv::Mat& m, const std::string& s, int x, int y, double scale = 0.42) {
  cv::putText(m, s, {x, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0), 1, cv::LINE_AA);
}

// 1, 2 or 5 times a power of ten, about `ticks` steps over `span`.
double nice_step(double span, double ticks) {
  if (!(span > 0)) return 1.0;
  const double raw = span / ticks;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0})
    if (raw <= f * p) return f * p;
  return 10.0 * p;
}

}  // namespace

Image vector_slice_plot(const VectorSlice& s, VectorSliceLayout* layout) {
  const std::size_t nodes = static_cast<std::size_t>(s.nx) * static_cast<std::size_t>(std::max(s.ny, 0));
  if (s.nx <= 0 || s.ny <= 0 || s.displacement.size() != nodes || s.valid.size() != nodes)
    throw bad_input("vector slice plot: the slice is empty or its arrays do not match nx * ny");
  const int cell = std::clamp(640 / std::max(s.nx, s.ny), 6, 40);
  const int pw = s.nx * cell, ph = s.ny * cell;
  const int bar_left = kLeft + pw + kBarGap;
  const int width = bar_left + kBarWidth + kBarLabels, height = kTop + ph + kBottom;
  cv::Mat m(height, width, CV_8UC1, cv::Scalar(255));

  double largest = 0.0;
  for (std::size_t n = 0; n < nodes; ++n)
    if (s.valid[n]) largest = std::max(largest, std::hypot(s.displacement[n].x, s.displacement[n].y));
  const auto grey_of = [&](double magnitude) {
    return largest > 0 ? kLowestGrey + (255 - kLowestGrey) * std::min(magnitude / largest, 1.0) : 255.0;
  };
  // Arrow length in pixels per voxel: the largest displacement spans 0.9 of a cell.
  const double px_per_voxel = largest > 0 ? 0.9 * cell / largest : 0.0;

  // Cells (row j = 0 at the bottom, as on a plot), then arrows on top.
  const auto cell_origin = [&](int i, int j) { return cv::Point(kLeft + i * cell, kTop + (s.ny - 1 - j) * cell); };
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      const std::size_t n = static_cast<std::size_t>(i) + static_cast<std::size_t>(s.nx) * j;
      const Vec3d& d = s.displacement[n];
      const double grey = s.valid[n] ? grey_of(std::hypot(d.x, d.y)) : kInvalidGrey;
      const cv::Point o = cell_origin(i, j);
      cv::rectangle(m, o, {o.x + cell - 1, o.y + cell - 1}, cv::Scalar(grey), cv::FILLED);
    }
  for (int j = 0; j < s.ny; ++j)
    for (int i = 0; i < s.nx; ++i) {
      const std::size_t n = static_cast<std::size_t>(i) + static_cast<std::size_t>(s.nx) * j;
      if (!s.valid[n] || px_per_voxel <= 0) continue;
      const cv::Point o = cell_origin(i, j);
      const cv::Point2d c(o.x + cell / 2.0, o.y + cell / 2.0);
      const cv::Point2d tip(c.x + s.displacement[n].x * px_per_voxel, c.y - s.displacement[n].y * px_per_voxel);
      if (std::hypot(tip.x - c.x, tip.y - c.y) >= 1.0)
        cv::arrowedLine(m, c, tip, cv::Scalar(0), 1, cv::LINE_AA, 0, 0.3);
    }
  cv::rectangle(m, {kLeft - 1, kTop - 1}, {kLeft + pw, kTop + ph}, cv::Scalar(0), 1);

  // Axes: ticks at node positions, labelled in the axis unit.
  const double tick = std::max(1.0, std::round(nice_step(std::max(s.nx, s.ny) - 1.0, 6.0)));
  for (int i = 0; i < s.nx; i += static_cast<int>(tick)) {
    const int x = kLeft + i * cell + cell / 2;
    cv::line(m, {x, kTop + ph}, {x, kTop + ph + 5}, cv::Scalar(0), 1);
    text(m, fmt::format("{:.3g}", s.x0 + i * s.spacing), x - 10, kTop + ph + 20);
  }
  for (int j = 0; j < s.ny; j += static_cast<int>(tick)) {
    const int y = kTop + (s.ny - 1 - j) * cell + cell / 2;
    cv::line(m, {kLeft - 5, y}, {kLeft, y}, cv::Scalar(0), 1);
    text(m, fmt::format("{:.3g}", s.y0 + j * s.spacing), 8, y + 4);
  }
  text(m, fmt::format("x [{}]", s.axis_unit), kLeft + pw / 2 - 20, kTop + ph + 40, 0.45);
  text(m, fmt::format("y [{}]", s.axis_unit), 8, kTop - 10, 0.45);
  if (!s.title.empty()) text(m, s.title, kLeft, 22, 0.5);

  // Scale: a reference arrow of a round displacement, and what black means.
  if (largest > 0) {
    const double ref = nice_step(largest, 2.0);
    const int y = kTop + ph + 65;
    cv::arrowedLine(m, {kLeft, y}, {kLeft + static_cast<int>(std::lround(ref * px_per_voxel)), y}, cv::Scalar(0), 1,
                    cv::LINE_AA, 0, 0.3);
    text(m, fmt::format("{:g} voxel (in-plane)", ref), kLeft + static_cast<int>(ref * px_per_voxel) + 10, y + 4);
  }
  cv::rectangle(m, {kLeft + pw - 150, kTop + ph + 56}, {kLeft + pw - 140, kTop + ph + 66}, cv::Scalar(0), cv::FILLED);
  text(m, "no valid vector", kLeft + pw - 134, kTop + ph + 66);

  // Colour bar: grey level against in-plane magnitude, 0 at the bottom.
  for (int y = 0; y < ph; ++y) {
    const double magnitude = largest * (ph - 1 - y) / std::max(ph - 1, 1);
    cv::line(m, {bar_left, kTop + y}, {bar_left + kBarWidth - 1, kTop + y}, cv::Scalar(grey_of(magnitude)), 1);
  }
  cv::rectangle(m, {bar_left - 1, kTop - 1}, {bar_left + kBarWidth, kTop + ph}, cv::Scalar(0), 1);
  const double bar_step = nice_step(largest, 4.0);
  for (double v = 0.0; largest > 0 && v <= largest * (1 + 1e-9); v += bar_step) {
    const int y = kTop + ph - 1 - static_cast<int>(std::lround(v / largest * (ph - 1)));
    cv::line(m, {bar_left + kBarWidth, y}, {bar_left + kBarWidth + 4, y}, cv::Scalar(0), 1);
    text(m, fmt::format("{:g}", v), bar_left + kBarWidth + 7, y + 4);
  }
  text(m, "|d| voxel", bar_left - 10, kTop - 10, 0.42);

  if (layout) *layout = {cell, kLeft, kTop, bar_left, kTop, kBarWidth, ph};
  Image out = Image::allocate(width, height, SampleType::u8);
  for (int y = 0; y < height; ++y) std::memcpy(out.row<std::uint8_t>(y), m.ptr(y), static_cast<std::size_t>(width));
  return out;
}

}  // namespace tomorig::quicklook
