#include "tomorig/processing/quality/depth_profile_plot.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

constexpr int kWidth = 820, kHeight = 480;
constexpr int kLeft = 90, kRight = 130, kTop = 40, kBottom = 60;

void text(cv::Mat& m, const std::string& s, int x, int y, double scale = 0.42) {
  cv::putText(m, s, {x, y}, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0), 1, cv::LINE_AA);
}

double nice_step(double span) {
  if (!(span > 0)) return 1.0;
  const double raw = span / 6.0;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double f : {1.0, 2.0, 5.0, 10.0})
    if (raw <= f * p) return f * p;
  return 10.0 * p;
}

}  // namespace

std::vector<double> mean_intensity_per_slice(const SparseVolume& v) {
  const VoxelGrid& g = v.grid;
  std::vector<double> sums(static_cast<std::size_t>(std::max(g.nz, 0)), 0.0);
  const std::uint64_t per_slice = static_cast<std::uint64_t>(g.nx) * static_cast<std::uint64_t>(g.ny);
  if (per_slice == 0) return sums;
  for (std::size_t n = 0; n < v.index.size(); ++n) {
    const std::uint64_t k = v.index[n] / per_slice;
    if (k < sums.size()) sums[k] += v.intensity[n];
  }
  for (double& s : sums) s /= static_cast<double>(per_slice);
  return sums;
}

Image depth_profile_plot(const std::vector<DepthCurve>& curves, const std::string& title) {
  if (curves.empty()) throw bad_input("depth profile plot: no curve");
  double z0 = 1e300, z1 = -1e300, top = 0.0;
  for (const DepthCurve& c : curves) {
    if (c.z_mm.empty() || c.z_mm.size() != c.values.size())
      throw bad_input(fmt::format("depth profile plot: curve '{}' is empty or its z and values differ in length", c.label));
    for (double z : c.z_mm) z0 = std::min(z0, z), z1 = std::max(z1, z);
    for (double v : c.values)
      if (std::isfinite(v)) top = std::max(top, v);
  }
  if (z1 <= z0) z0 -= 1.0, z1 += 1.0;
  const double ystep = nice_step(top > 0 ? top * 1.05 : 1.0);
  const double ytop = std::max(ystep, std::ceil((top > 0 ? top * 1.05 : 1.0) / ystep) * ystep);

  cv::Mat m(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  const int pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  const auto px = [&](double z) { return kLeft + static_cast<int>(std::lround((z - z0) / (z1 - z0) * pw)); };
  const auto py = [&](double v) { return kTop + ph - static_cast<int>(std::lround(std::clamp(v / ytop, 0.0, 1.0) * ph)); };
  for (double v = 0.0; v <= ytop * (1 + 1e-9); v += ystep) {
    cv::line(m, {kLeft, py(v)}, {kLeft + pw, py(v)}, cv::Scalar(225), 1);
    text(m, fmt::format("{:.3g}", v), 10, py(v) + 4);
  }
  const double zstep = nice_step(z1 - z0);
  for (double z = std::ceil(z0 / zstep) * zstep; z <= z1 + 1e-9; z += zstep) {
    cv::line(m, {px(z), kTop}, {px(z), kTop + ph}, cv::Scalar(225), 1);
    text(m, fmt::format("{:.3g}", std::abs(z) < 1e-12 ? 0.0 : z), px(z) - 12, kTop + ph + 20);
  }
  cv::rectangle(m, {kLeft, kTop}, {kLeft + pw, kTop + ph}, cv::Scalar(0), 1);
  text(m, "z [mm]", kLeft + pw / 2 - 20, kTop + ph + 45, 0.45);
  text(m, "mean intensity per voxel", 10, kTop - 12, 0.45);
  if (!title.empty()) text(m, title, kLeft + 170, kTop - 12, 0.45);

  // One curve per volume: solid black, then grey, then dashed; the legend sits right.
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const int grey = c % 2 == 0 ? 0 : 130;
    const bool dashed = (c / 2) % 2 == 1;
    const DepthCurve& curve = curves[c];
    for (std::size_t k = 1; k < curve.values.size(); ++k) {
      if (dashed && k % 2 == 0) continue;
      cv::line(m, {px(curve.z_mm[k - 1]), py(curve.values[k - 1])}, {px(curve.z_mm[k]), py(curve.values[k])},
               cv::Scalar(grey), 2, cv::LINE_AA);
    }
    const int ly = kTop + 20 + static_cast<int>(c) * 22;
    cv::line(m, {kLeft + pw + 15, ly}, {kLeft + pw + 45, ly}, cv::Scalar(grey), 2, cv::LINE_AA);
    text(m, curve.label, kLeft + pw + 52, ly + 4);
  }

  Image out = Image::allocate(kWidth, kHeight, SampleType::u8);
  for (int y = 0; y < kHeight; ++y) std::memcpy(out.row<std::uint8_t>(y), m.ptr(y), kWidth);
  return out;
}

}  // namespace tomorig::quality
