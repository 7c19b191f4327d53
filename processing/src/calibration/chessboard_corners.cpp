// X-corner candidates and sub-pixel refinement for the chessboard detector.
#include "chessboard_corners.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <numbers>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"

namespace tomorig::calibration::chessboard {

namespace {

cv::Mat as_mat(const GreyImage& grey) {
  return cv::Mat(grey.height, grey.width, CV_32F, const_cast<float*>(grey.pixels.data()));
}

// Percentile of a sample of the image (every k-th pixel keeps this cheap on 5 Mpixel images).
float percentile(std::vector<float> values, double q) {
  if (values.empty()) return 0;
  auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

bool inside(const GreyImage& g, const Vec2d& p, double margin) {
  return p.x >= margin && p.y >= margin && p.x <= g.width - 1 - margin && p.y <= g.height - 1 - margin;
}

// Four alternating sectors on a ring of radius r, opposite sectors alike: an X-corner.
bool looks_like_x_corner(const GreyImage& g, const Vec2d& p, double r) {
  if (!inside(g, p, r + 1)) return false;
  constexpr int n = 32;
  double v[n];
  double lo = 1e30, hi = -1e30, mean = 0;
  for (int k = 0; k < n; ++k) {
    const double t = 2 * std::numbers::pi * k / n;
    v[k] = g.sample(p.x + r * std::cos(t), p.y + r * std::sin(t));
    lo = std::min(lo, v[k]);
    hi = std::max(hi, v[k]);
    mean += v[k];
  }
  mean /= n;
  const double contrast = hi - lo;
  if (contrast < 0.2) return false;  // grey levels are normalised: squares differ by ~1
  int changes = 0;
  double asymmetry = 0;
  for (int k = 0; k < n; ++k) {
    if ((v[k] > mean) != (v[(k + 1) % n] > mean)) ++changes;
    asymmetry += std::abs(v[k] - v[(k + n / 2) % n]);
  }
  asymmetry /= n;
  return changes == 4 && asymmetry < 0.25 * contrast;
}

}  // namespace

double GreyImage::sample(double x, double y) const {
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, width - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, height - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = &pixels[static_cast<std::size_t>(y0) * width + x0];
  const float* r1 = r0 + width;
  return (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
}

GreyImage normalised_grey(const Image& image) {
  if (image.empty() || image.width() < 8 || image.height() < 8)
    throw bad_input("chessboard detection needs an image of at least 8 x 8 pixels");
  GreyImage g;
  g.width = image.width();
  g.height = image.height();
  g.pixels.resize(static_cast<std::size_t>(g.width) * g.height);
  for (int y = 0; y < g.height; ++y) {
    float* out = &g.pixels[static_cast<std::size_t>(y) * g.width];
    switch (image.type()) {
      case SampleType::u8: {
        const auto* in = image.row<std::uint8_t>(y);
        for (int x = 0; x < g.width; ++x) out[x] = in[x];
        break;
      }
      case SampleType::u16: {
        const auto* in = image.row<std::uint16_t>(y);
        for (int x = 0; x < g.width; ++x) out[x] = in[x];
        break;
      }
      case SampleType::f32: {
        const auto* in = image.row<float>(y);
        for (int x = 0; x < g.width; ++x) out[x] = in[x];
        break;
      }
    }
  }
  std::vector<float> sample;
  const std::size_t stride = std::max<std::size_t>(1, g.pixels.size() / 200000);
  for (std::size_t i = 0; i < g.pixels.size(); i += stride) sample.push_back(g.pixels[i]);
  const float dark = percentile(sample, 0.02), light = percentile(sample, 0.98);
  if (!(light > dark)) throw bad_input("chessboard detection: the image is uniform (no target visible)");
  const float scale = 1.0f / (light - dark);
  for (float& v : g.pixels) v = (v - dark) * scale;
  return g;
}

std::vector<Candidate> find_x_corner_candidates(const GreyImage& grey, double& spacing_px) {
  cv::Mat src = as_mat(grey), smooth, ixx, iyy, ixy;
  cv::GaussianBlur(src, smooth, cv::Size(0, 0), 1.5);
  cv::Sobel(smooth, ixx, CV_32F, 2, 0, 3);
  cv::Sobel(smooth, iyy, CV_32F, 0, 2, 3);
  cv::Sobel(smooth, ixy, CV_32F, 1, 1, 3);
  cv::Mat response = ixy.mul(ixy) - ixx.mul(iyy);
  cv::Mat dilated;
  cv::dilate(response, dilated, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(7, 7)));
  double max_response = 0;
  cv::minMaxLoc(response, nullptr, &max_response);
  const float threshold = static_cast<float>(0.1 * max_response);

  std::vector<Candidate> raw;
  for (int y = 4; y < grey.height - 4; ++y) {
    const float* r = response.ptr<float>(y);
    const float* d = dilated.ptr<float>(y);
    for (int x = 4; x < grey.width - 4; ++x)
      if (r[x] > threshold && r[x] >= d[x]) raw.push_back({{double(x), double(y)}, r[x]});
  }
  // Plateaus give several equal maxima; keep the strongest within 3 pixels.
  std::sort(raw.begin(), raw.end(), [](const Candidate& a, const Candidate& b) { return a.response > b.response; });
  std::vector<Candidate> kept;
  for (const Candidate& c : raw) {
    bool near = false;
    for (const Candidate& k : kept)
      if (std::abs(k.pixel.x - c.pixel.x) <= 3 && std::abs(k.pixel.y - c.pixel.y) <= 3) { near = true; break; }
    if (!near) kept.push_back(c);
    if (kept.size() > 20000) break;  // a pathological image; the lattice check sorts it out
  }
  // Typical spacing: median nearest-neighbour distance.
  std::vector<double> nn;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    double best = 1e30;
    for (std::size_t j = 0; j < kept.size(); ++j)
      if (j != i) best = std::min(best, length(kept[i].pixel - kept[j].pixel));
    if (best < 1e30) nn.push_back(best);
  }
  spacing_px = nn.empty() ? 10.0 : percentile(std::vector<float>(nn.begin(), nn.end()), 0.5);
  const double ring = std::clamp(0.3 * spacing_px, 2.5, 12.0);
  std::vector<Candidate> out;
  for (const Candidate& c : kept)
    if (looks_like_x_corner(grey, c.pixel, ring)) out.push_back(c);
  return out;
}

int corner_polarity(const GreyImage& grey, const Vec2d& p, const Vec2d& step_a, const Vec2d& step_b) {
  const Vec2d d1 = 0.3 * (step_a + step_b), d2 = 0.3 * (step_a - step_b);
  const Vec2d pts[4] = {p + d1, p - d1, p + d2, p - d2};
  for (const Vec2d& q : pts)
    if (!inside(grey, q, 0)) return 0;
  const double diff = grey.sample(pts[0].x, pts[0].y) + grey.sample(pts[1].x, pts[1].y) -
                      grey.sample(pts[2].x, pts[2].y) - grey.sample(pts[3].x, pts[3].y);
  if (std::abs(diff) < 0.4) return 0;  // light minus dark ~2 for two quadrant pairs
  return diff > 0 ? 1 : -1;
}

bool refine_corner(const GreyImage& grey, Vec2d& p, const Vec2d& line_a, const Vec2d& line_b, double radius) {
  const int r = static_cast<int>(std::floor(radius));
  if (r < 2 || !inside(grey, p, r + 1)) return false;
  // Window pixels (centres at integer coordinates) within the radius of the start point.
  std::vector<Vec2d> xy;
  std::vector<double> value;
  const int x0 = static_cast<int>(std::lround(p.x)), y0 = static_cast<int>(std::lround(p.y));
  for (int y = y0 - r; y <= y0 + r; ++y)
    for (int x = x0 - r; x <= x0 + r; ++x)
      if ((x - p.x) * (x - p.x) + (y - p.y) * (y - p.y) <= radius * radius) {
        xy.push_back({double(x), double(y)});
        value.push_back(grey.at(x, y));
      }
  const std::size_t n = xy.size();
  // Parameters: px, py, theta1, theta2, sigma, c, a.
  double q[7] = {p.x, p.y, std::atan2(line_a.y, line_a.x), std::atan2(line_b.y, line_b.x), 1.0, 0.0, 0.0};
  auto evaluate = [&](const double* v, std::vector<double>* res, double (*jac)[7]) {
    const double n1x = -std::sin(v[2]), n1y = std::cos(v[2]), n2x = -std::sin(v[3]), n2y = std::cos(v[3]);
    const double s = std::abs(v[4]) + 1e-3, k = 1 / (std::numbers::sqrt2 * s);
    const double g0 = 2 / std::sqrt(std::numbers::pi) * k;
    double cost = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double dx = xy[i].x - v[0], dy = xy[i].y - v[1];
      const double d1 = n1x * dx + n1y * dy, d2 = n2x * dx + n2y * dy;
      const double e1 = std::erf(d1 * k), e2 = std::erf(d2 * k);
      const double m = v[5] + v[6] * e1 * e2;
      const double ri = m - value[i];
      cost += ri * ri;
      if (res) (*res)[i] = ri;
      if (jac) {
        const double g1 = g0 * std::exp(-d1 * d1 * k * k), g2 = g0 * std::exp(-d2 * d2 * k * k);
        const double a = v[6];
        jac[i][0] = -a * (g1 * e2 * n1x + e1 * g2 * n2x);
        jac[i][1] = -a * (g1 * e2 * n1y + e1 * g2 * n2y);
        jac[i][2] = a * g1 * e2 * (-std::cos(v[2]) * dx - std::sin(v[2]) * dy);
        jac[i][3] = a * e1 * g2 * (-std::cos(v[3]) * dx - std::sin(v[3]) * dy);
        jac[i][4] = -a * (g1 * e2 * d1 + e1 * g2 * d2) / s;
        jac[i][5] = 1;
        jac[i][6] = e1 * e2;
      }
    }
    return cost;
  };
  // Start c and a by linear regression of the pixels on e1 e2.
  {
    std::vector<double> res(n);
    std::vector<std::array<double, 7>> J(n);
    evaluate(q, &res, reinterpret_cast<double(*)[7]>(J.data()));
    double sxx = 0, sx = 0, sy = 0, sxy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double e = J[i][6];
      sxx += e * e, sx += e, sy += value[i], sxy += e * value[i];
    }
    const double det = n * sxx - sx * sx;
    if (std::abs(det) < 1e-12) return false;
    q[6] = (n * sxy - sx * sy) / det;
    q[5] = (sy - q[6] * sx) / n;
  }
  std::vector<double> res(n);
  std::vector<std::array<double, 7>> J(n);
  double lambda = 1e-3;
  double cost = evaluate(q, &res, reinterpret_cast<double(*)[7]>(J.data()));
  for (int iteration = 0; iteration < 40; ++iteration) {
    cv::Matx<double, 7, 7> A = cv::Matx<double, 7, 7>::zeros();
    cv::Vec<double, 7> g = cv::Vec<double, 7>::all(0);
    for (std::size_t i = 0; i < n; ++i)
      for (int a = 0; a < 7; ++a) {
        g[a] -= J[i][a] * res[i];
        for (int b = a; b < 7; ++b) A(a, b) += J[i][a] * J[i][b];
      }
    for (int a = 0; a < 7; ++a)
      for (int b = 0; b < a; ++b) A(a, b) = A(b, a);
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      cv::Matx<double, 7, 7> D = A;
      for (int a = 0; a < 7; ++a) D(a, a) += lambda * (A(a, a) + 1e-12);
      cv::Vec<double, 7> step;
      if (!cv::solve(D, g, step, cv::DECOMP_CHOLESKY)) {
        lambda *= 10;
        continue;
      }
      double trial[7];
      for (int a = 0; a < 7; ++a) trial[a] = q[a] + step[a];
      const double c = evaluate(trial, nullptr, nullptr);
      if (c < cost) {
        std::copy(trial, trial + 7, q);
        const double old = cost;
        cost = evaluate(q, &res, reinterpret_cast<double(*)[7]>(J.data()));
        lambda = std::max(lambda * 0.3, 1e-9);
        improved = true;
        if (std::abs(step[0]) + std::abs(step[1]) < 1e-6 && old - cost < 1e-12 * old) iteration = 1000;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  const Vec2d refined{q[0], q[1]};
  if (!std::isfinite(refined.x) || !std::isfinite(refined.y) || length(refined - p) > 0.5 * radius) return false;
  p = refined;
  return true;
}

}  // namespace tomorig::calibration::chessboard
