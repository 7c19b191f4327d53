#pragma once
// Drawing helpers shared by the optics plots (visibility_plot.cpp, psf_plot.cpp): 8-bit grey
// OpenCV canvases.
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

namespace tomorig::optics::plot {

inline void text(cv::Mat& m, const std::string& s, int x, int y, double scale = 0.45) {
  cv::putText(m, s, {x, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0), 1, cv::LINE_AA);
}

// A "nice" tick step for a span: 1, 2 or 5 times a power of ten, about 6 ticks.
inline double tick_step(double span) {
  const double raw = span / 6.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0})
    if (raw <= f * p) return f * p;
  return 10.0 * p;
}

inline void marker(cv::Mat& m, cv::Point p, int kind, int grey) {
  const cv::Scalar c(grey);
  switch (kind % 4) {
    case 0: cv::circle(m, p, 4, c, 1, cv::LINE_AA); break;
    case 1: cv::rectangle(m, {p.x - 4, p.y - 4}, {p.x + 4, p.y + 4}, c, 1); break;
    case 2:
      cv::line(m, {p.x - 4, p.y + 4}, {p.x, p.y - 4}, c, 1, cv::LINE_AA);
      cv::line(m, {p.x, p.y - 4}, {p.x + 4, p.y + 4}, c, 1, cv::LINE_AA);
      cv::line(m, {p.x + 4, p.y + 4}, {p.x - 4, p.y + 4}, c, 1, cv::LINE_AA);
      break;
    default:
      cv::line(m, {p.x - 4, p.y - 4}, {p.x + 4, p.y + 4}, c, 1, cv::LINE_AA);
      cv::line(m, {p.x - 4, p.y + 4}, {p.x + 4, p.y - 4}, c, 1, cv::LINE_AA);
  }
}

}  // namespace tomorig::optics::plot
