// draw_detection_overlay: the image dimmed, then the detection drawn on it with OpenCV.
#include "tomorig/processing/calibration/target_overlay.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tomorig::calibration {
namespace {

// The image's grey levels mapped to 0..160, so that white marks stand out everywhere.
cv::Mat dimmed(const Image& image) {
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(image.width()) * image.height());
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) values.push_back(image.value(x, y));
  const auto at = [&](double q) {
    auto it = values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), it, values.end());
    return *it;
  };
  const double lo = at(0.01), hi = std::max(at(0.999), lo + 1);
  cv::Mat out(image.height(), image.width(), CV_8U);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(std::clamp((image.value(x, y) - lo) / (hi - lo), 0.0, 1.0) * 160);
  return out;
}

cv::Point2d to_cv(Vec2d p) { return {p.x, p.y}; }

// Sub-pixel drawing: OpenCV's fixed-point shift of 4 bits (1/16 px).
constexpr int kShift = 4;
cv::Point fixed(cv::Point2d p) { return {static_cast<int>(std::lround(p.x * 16)), static_cast<int>(std::lround(p.y * 16))}; }

void arrow(cv::Mat& m, Vec2d from, Vec2d step, double length_px, const char* label) {
  const double n = std::hypot(step.x, step.y);
  if (!(n > 0)) return;
  const cv::Point2d a = to_cv(from), b{from.x + step.x / n * length_px, from.y + step.y / n * length_px};
  cv::arrowedLine(m, fixed(a), fixed(b), cv::Scalar(0), 4, cv::LINE_AA, kShift, 0.15);
  cv::arrowedLine(m, fixed(a), fixed(b), cv::Scalar(255), 2, cv::LINE_AA, kShift, 0.15);
  const cv::Point text{static_cast<int>(b.x + 4), static_cast<int>(b.y + 4)};
  cv::putText(m, label, text, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0), 3, cv::LINE_AA);
  cv::putText(m, label, text, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255), 1, cv::LINE_AA);
}

}  // namespace

Image draw_detection_overlay(const Image& image, const TargetDetection& detection) {
  cv::Mat m = dimmed(image);
  for (const PointCorrespondence& p : detection.points) {
    cv::circle(m, fixed(to_cv(p.pixel)), 4 << kShift, cv::Scalar(255), 1, cv::LINE_AA, kShift);
    cv::line(m, fixed({p.pixel.x - 1.5, p.pixel.y}), fixed({p.pixel.x + 1.5, p.pixel.y}), cv::Scalar(255), 1, cv::LINE_AA, kShift);
    cv::line(m, fixed({p.pixel.x, p.pixel.y - 1.5}), fixed({p.pixel.x, p.pixel.y + 1.5}), cv::Scalar(255), 1, cv::LINE_AA, kShift);
  }
  if (detection.origin_px) {
    const Vec2d o = *detection.origin_px;
    cv::circle(m, fixed(to_cv(o)), 9 << kShift, cv::Scalar(0), 4, cv::LINE_AA, kShift);
    cv::circle(m, fixed(to_cv(o)), 9 << kShift, cv::Scalar(255), 2, cv::LINE_AA, kShift);
    const double length = std::max(30.0, 0.12 * std::min(image.width(), image.height()));
    if (detection.x_step_px) arrow(m, o, *detection.x_step_px, 1.5 * length, "x");
    if (detection.y_step_px) arrow(m, o, *detection.y_step_px, length, "y");
  }
  Image out = Image::allocate(image.width(), image.height(), SampleType::u8);
  for (int y = 0; y < image.height(); ++y) std::copy_n(m.ptr<std::uint8_t>(y), image.width(), out.row<std::uint8_t>(y));
  return out;
}

}  // namespace tomorig::calibration
