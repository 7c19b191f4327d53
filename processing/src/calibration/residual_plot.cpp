#include "tomorig/processing/calibration/residual_plot.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

constexpr int kMargin = 40;  // above the image area: title and legend

// 1, 2 or 5 times a power of ten, at most `value`: magnifications a reader can use.
double round_down_to_125(double value) {
  const double p = std::pow(10.0, std::floor(std::log10(value)));
  for (double f : {5.0, 2.0, 1.0})
    if (f * p <= value) return f * p;
  return p;
}

}  // namespace

ResidualPlot residual_plot(const CameraModel& model, std::span<const PointCorrespondence> points, ImageSize size,
                           const std::string& title, int max_side) {
  if (points.empty()) throw bad_input(fmt::format("residual plot '{}': no points", title));
  if (size.width <= 0 || size.height <= 0 || max_side < 100)
    throw bad_input(fmt::format("residual plot '{}': image size {} x {} is invalid", title, size.width, size.height));
  const double scale = std::min(1.0, static_cast<double>(max_side) / std::max(size.width, size.height));
  const int w = std::max(1, static_cast<int>(std::lround(size.width * scale)));
  const int h = std::max(1, static_cast<int>(std::lround(size.height * scale)));

  ResidualPlot out;
  std::vector<Vec2d> projected(points.size());
  double squares = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    projected[k] = model.project(points[k].world);
    const double d = std::hypot(projected[k].x - points[k].pixel.x, projected[k].y - points[k].pixel.y);
    squares += d * d;
    out.max_px = std::max(out.max_px, d);
  }
  out.rms_px = std::sqrt(squares / static_cast<double>(points.size()));
  // The largest arrow spans about 1/15 of the picture's shorter side.
  const double wanted = std::min(w, h) / 15.0 / scale;
  out.magnification = out.max_px > 0 ? std::max(1.0, round_down_to_125(wanted / out.max_px)) : 1.0;

  cv::Mat m(h + kMargin, w, CV_8UC1, cv::Scalar(255));
  cv::rectangle(m, {0, kMargin}, {w - 1, kMargin + h - 1}, cv::Scalar(160), 1);
  const auto at = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(x * scale)), kMargin + static_cast<int>(std::lround(y * scale)));
  };
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Vec2d p = points[k].pixel;
    const Vec2d tip{p.x + out.magnification * (projected[k].x - p.x), p.y + out.magnification * (projected[k].y - p.y)};
    cv::circle(m, at(p.x, p.y), 2, cv::Scalar(110), cv::FILLED, cv::LINE_AA);
    cv::arrowedLine(m, at(p.x, p.y), at(tip.x, tip.y), cv::Scalar(0), 1, cv::LINE_AA, 0, 0.25);
  }
  cv::putText(m, title, {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0), 1, cv::LINE_AA);
  cv::putText(m,
              fmt::format("arrows x{:g}: point -> model; RMS {:.3g} px, max {:.3g} px", out.magnification, out.rms_px,
                          out.max_px),
              {6, 33}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0), 1, cv::LINE_AA);

  out.image = Image::allocate(m.cols, m.rows, SampleType::u8);
  for (int y = 0; y < m.rows; ++y) std::memcpy(out.image.row<std::uint8_t>(y), m.ptr(y), static_cast<std::size_t>(m.cols));
  return out;
}

}  // namespace tomorig::calibration
