// Blob stage of the dot-grid detector. The background is removed with a grey-level opening
// (a dot is smaller than the structuring element, uneven illumination is not), the result is
// thresholded by Otsu's method, and each connected component is classified:
//  - a dot: compact (fills much of its bounding box), not touching the image border;
//  - the origin marker: a hollow component (a square frame) with a dot inside its box;
//  - a filled marker: a solid component clearly larger than a dot that fills its smallest
//    enclosing rectangle (a square, seen in perspective) or triangle (a triangle).
// Centres are intensity-weighted centroids of the background-free image over the component
// grown by two pixels, so the faint rim of a dot counts and the threshold does not bias them.
#include "dot_grid_blobs.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tomorig::calibration::detail {
namespace {

cv::Mat to_float(const Image& image) {
  cv::Mat out(image.height(), image.width(), CV_32F);
  for (int y = 0; y < image.height(); ++y) {
    float* row = out.ptr<float>(y);
    for (int x = 0; x < image.width(); ++x) row[x] = static_cast<float>(image.value(x, y));
  }
  return out;
}

struct Component {
  int label = 0;
  cv::Rect box;
  int area = 0;
  double fill() const { return static_cast<double>(area) / (static_cast<double>(box.width) * box.height); }
  bool touches_border(const cv::Size& size) const {
    return box.x == 0 || box.y == 0 || box.x + box.width == size.width || box.y + box.height == size.height;
  }
};

// Intensity-weighted centroid over the component's pixels and the background pixels within
// `grow` of its box (pixels of other components are excluded).
Vec2d weighted_centroid(const cv::Mat& signal, const cv::Mat& labels, const Component& c, int grow) {
  const cv::Rect window = (c.box + cv::Size(2 * grow, 2 * grow) - cv::Point(grow, grow)) & cv::Rect(0, 0, signal.cols, signal.rows);
  double sum = 0, sx = 0, sy = 0;
  for (int y = window.y; y < window.y + window.height; ++y) {
    const float* s = signal.ptr<float>(y);
    const int* l = labels.ptr<int>(y);
    for (int x = window.x; x < window.x + window.width; ++x) {
      if (l[x] != c.label && l[x] != 0) continue;
      const double w = std::max(0.0f, s[x]);
      sum += w;
      sx += w * x;
      sy += w * y;
    }
  }
  if (sum <= 0) return {c.box.x + 0.5 * (c.box.width - 1), c.box.y + 0.5 * (c.box.height - 1)};
  return {sx / sum, sy / sum};
}

// Ratio of the principal axes of a component's pixel distribution (1 for a disc).
double axis_ratio(const cv::Mat& labels, const Component& c) {
  const cv::Moments m = cv::moments(labels(c.box) == c.label, true);
  if (m.m00 <= 0) return 1;
  const double a = m.mu20 / m.m00, b = m.mu11 / m.m00, d = m.mu02 / m.m00;
  const double root = std::sqrt(0.25 * (a - d) * (a - d) + b * b);
  const double major = 0.5 * (a + d) + root, minor = 0.5 * (a + d) - root;
  return minor > 0 ? std::sqrt(major / minor) : 1e9;
}

// A filled square or triangle, from the shape of the component's outline: how much of its
// smallest enclosing rectangle and triangle it fills (a disc fills 0.785 and ~0.6, a square
// ~1 and 0.5, a triangle ~0.5 and ~1; perspective keeps squares and triangles near 1).
std::optional<MarkerShape> filled_shape(const cv::Mat& labels, const Component& c) {
  const cv::Mat mask = labels(c.box) == c.label;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.size() != 1 || contours[0].size() < 6) return std::nullopt;
  std::vector<cv::Point2f> outline(contours[0].begin(), contours[0].end());
  // Pixel outlines run through the edge pixels' centres; half a pixel all round is the area
  // they leave out, which matters for the marker sizes of a few tens of pixels.
  const double area = cv::contourArea(outline) + 0.5 * cv::arcLength(outline, true);
  const cv::RotatedRect rect = cv::minAreaRect(outline);
  const double rect_area = (rect.size.width + 1.0) * (rect.size.height + 1.0);
  std::vector<cv::Point2f> triangle;
  const double triangle_area = cv::minEnclosingTriangle(outline, triangle);
  if (!(rect_area > 0) || !(triangle_area > 0)) return std::nullopt;
  const double rect_fill = area / rect_area;
  const double aspect = std::max(rect.size.width, rect.size.height) / std::max(1.0f, std::min(rect.size.width, rect.size.height));

  const double triangle_fill = area / (triangle_area + 0.5 * cv::arcLength(triangle, true));
  if (rect_fill > 0.84 && triangle_fill < 0.65 && aspect < 1.8) return MarkerShape::filled_square;
  if (triangle_fill > 0.76 && rect_fill < 0.65) return MarkerShape::triangle;
  return std::nullopt;
}

double solidity(const cv::Mat& labels, const Component& c) {
  const cv::Mat mask = labels(c.box) == c.label;
  std::vector<cv::Point> points;
  cv::findNonZero(mask, points);
  if (points.size() < 3) return 1;
  std::vector<cv::Point> hull;
  cv::convexHull(points, hull);
  return static_cast<double>(c.area) / (cv::contourArea(hull) + 0.5 * cv::arcLength(hull, true) + 1);
}

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2), values.end());
  return values[values.size() / 2];
}

}  // namespace

DotBlobs find_dot_blobs(const Image& image, bool white_dots, double max_feature_px) {
  DotBlobs result;
  cv::Mat raw = to_float(image);
  if (!white_dots) {
    double lo = 0, hi = 0;
    cv::minMaxLoc(raw, &lo, &hi);
    raw = static_cast<float>(hi) - raw;
  }
  const int side = std::min(image.width(), image.height());
  int kernel = max_feature_px > 0 ? static_cast<int>(std::ceil(max_feature_px)) : std::max(15, side / 8);
  kernel |= 1;
  cv::Mat background;
  cv::morphologyEx(raw, background, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {kernel, kernel}));
  const cv::Mat signal = raw - background;

  double lo = 0, hi = 0;
  cv::minMaxLoc(signal, &lo, &hi);
  if (!(hi > 0)) return result;
  cv::Mat scaled;
  signal.convertTo(scaled, CV_8U, 255.0 / hi);
  cv::Mat binary;
  cv::threshold(scaled, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);

  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  std::vector<Component> compact, hollow;
  int border = 0;
  for (int k = 1; k < count; ++k) {
    Component c{k,
                {stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP), stats.at<int>(k, cv::CC_STAT_WIDTH),
                 stats.at<int>(k, cv::CC_STAT_HEIGHT)},
                stats.at<int>(k, cv::CC_STAT_AREA)};
    if (c.touches_border(binary.size())) {
      ++border;
      continue;
    }
    // A filled triangle fills at most half its box, like a frame; its outline is convex.
    if (c.fill() >= 0.45 || (c.box.width >= 5 && c.box.height >= 5 && solidity(labels, c) > 0.85))
      compact.push_back(c);
    else if (c.box.width >= 5 && c.box.height >= 5)
      hollow.push_back(c);
  }
  if (border > 0)
    result.warnings.push_back(fmt::format("{} blob(s) touching the image border dropped (cut off, centre unknown)", border));

  // Dots are alike in area; specks of noise and merged blobs are not.
  std::vector<double> areas;
  for (const Component& c : compact) areas.push_back(c.area);
  const double typical = median(areas);
  std::vector<Component> dots;
  int small = 0, large = 0, elongated = 0;
  for (const Component& c : compact) {
    // Markers are clearly larger than dots (docs/calibration.md: at least twice the area).
    if (c.area > 1.8 * typical && c.area >= 30)
      if (const std::optional<MarkerShape> shape = filled_shape(labels, c)) {
        result.markers.push_back({*shape, weighted_centroid(signal, labels, c, 2), -1});
        continue;
      }
    if (c.area < 0.25 * typical || c.area < 2) ++small;
    else if (c.area > 4 * typical) ++large;
    else if (c.area >= 6 && axis_ratio(labels, c) > 2.5) ++elongated;  // two dots run together, or a scratch
    else dots.push_back(c);
  }
  if (elongated > 0)
    result.warnings.push_back(fmt::format("{} elongated blob(s) dropped (two dots run together?)", elongated));
  if (small > 0) result.warnings.push_back(fmt::format("{} speck(s) much smaller than a dot ignored", small));
  if (large > 0) result.warnings.push_back(fmt::format("{} blob(s) much larger than a dot dropped (merged dots?)", large));

  for (const Component& c : dots) result.dots.push_back(weighted_centroid(signal, labels, c, 2));

  // The marker: a hollow component whose box holds exactly one dot, near the box centre. Its
  // frame may be much fainter than the dots (1/30 of them on the fluidimage target), so it is
  // looked for again above a low threshold: well clear of the noise, or 1 % of the peak.
  std::vector<float> values(signal.begin<float>(), signal.end<float>());
  const double centre = median(std::vector<double>(values.begin(), values.end()));
  for (float& v : values) v = std::abs(v - static_cast<float>(centre));
  const double noise = 1.4826 * median(std::vector<double>(values.begin(), values.end()));
  const double low = std::max(centre + 6 * noise, 0.01 * hi);
  cv::Mat faint = signal > low;
  cv::Mat faint_labels, faint_stats, faint_centroids;
  const int faint_count = cv::connectedComponentsWithStats(faint, faint_labels, faint_stats, faint_centroids, 8, CV_32S);
  for (int k = 1; k < faint_count; ++k) {
    Component c{k,
                {faint_stats.at<int>(k, cv::CC_STAT_LEFT), faint_stats.at<int>(k, cv::CC_STAT_TOP),
                 faint_stats.at<int>(k, cv::CC_STAT_WIDTH), faint_stats.at<int>(k, cv::CC_STAT_HEIGHT)},
                faint_stats.at<int>(k, cv::CC_STAT_AREA)};
    if (!c.touches_border(faint.size()) && c.fill() < 0.45 && c.box.width >= 5 && c.box.height >= 5) hollow.push_back(c);
  }
  std::vector<cv::Rect> seen;
  for (const Component& h : hollow) {
    const double cx = h.box.x + 0.5 * (h.box.width - 1), cy = h.box.y + 0.5 * (h.box.height - 1);
    std::vector<int> inside;
    for (std::size_t d = 0; d < result.dots.size(); ++d) {
      const Vec2d p = result.dots[d];
      if (std::abs(p.x - cx) < 0.3 * h.box.width && std::abs(p.y - cy) < 0.3 * h.box.height)
        inside.push_back(static_cast<int>(d));
    }
    if (inside.size() != 1) continue;
    // The same frame found at both thresholds counts once.
    if (std::any_of(seen.begin(), seen.end(), [&](const cv::Rect& r) { return (r & h.box).area() > 0; })) continue;
    seen.push_back(h.box);
    result.markers.push_back({MarkerShape::hollow_square, result.dots[static_cast<std::size_t>(inside.front())], inside.front()});
  }
  return result;
}

}  // namespace tomorig::calibration::detail
