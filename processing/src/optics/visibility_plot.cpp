#include "tomorig/processing/optics/visibility_plot.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "optics/plot_helpers.h"
#include "tomorig/core/error.h"

namespace tomorig::optics {
namespace {

constexpr int kWidth = 900, kHeight = 560;
constexpr int kLeft = 80, kRight = 200, kTop = 40, kBottom = 60;  // margins; the legend sits right
using plot::marker;
using plot::text;
using plot::tick_step;

}  // namespace

Image visibility_plot(const VisibilitySetup& setup, const std::vector<VisibilityRow>& rows) {
  if (rows.empty()) throw bad_input("visibility plot: the table has no rows");
  double z0 = rows.front().z_mm, z1 = rows.back().z_mm;
  if (z1 <= z0) {
    z0 -= 1.0;
    z1 += 1.0;
  }
  double dmax = 0.0;
  for (const VisibilityRow& r : rows)
    for (double d : r.d_min_um)
      if (std::isfinite(d)) dmax = std::max(dmax, d);
  if (dmax <= 0.0) dmax = setup.d_max_um;
  const double ystep = tick_step(dmax * 1.1);
  const double ytop = std::ceil(dmax * 1.1 / ystep) * ystep;

  cv::Mat m(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  const int pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  const auto px = [&](double z) { return kLeft + static_cast<int>(std::lround((z - z0) / (z1 - z0) * pw)); };
  const auto py = [&](double d) { return kTop + ph - static_cast<int>(std::lround(std::min(d, ytop) / ytop * ph)); };

  // Axes, grid and ticks.
  for (double d = 0.0; d <= ytop + 1e-9; d += ystep) {
    cv::line(m, {kLeft, py(d)}, {kLeft + pw, py(d)}, cv::Scalar(225), 1);
    text(m, fmt::format("{:g}", d), kLeft - 45, py(d) + 5);
  }
  const double zstep = tick_step(z1 - z0);
  for (double z = std::ceil(z0 / zstep) * zstep; z <= z1 + 1e-9; z += zstep) {
    cv::line(m, {px(z), kTop}, {px(z), kTop + ph}, cv::Scalar(225), 1);
    text(m, fmt::format("{:g}", std::abs(z) < 1e-12 ? 0.0 : z), px(z) - 12, kTop + ph + 20);
  }
  cv::rectangle(m, {kLeft, kTop}, {kLeft + pw, kTop + ph}, cv::Scalar(0), 1);
  text(m, "z [mm]", kLeft + pw / 2 - 25, kHeight - 15, 0.55);
  text(m, "d_min [um]", 5, kTop - 12, 0.55);
  text(m, fmt::format("Smallest visible droplet ({}, threshold 1 - 2 sigma)", setup.liquid.name), kLeft + 60, 25, 0.55);

  // One curve per camera, then the set-up's limit on top. Points that are not visible (or not
  // known) break the line.
  const std::size_t cams = setup.cameras.size();
  for (std::size_t c = 0; c <= cams; ++c) {
    const bool is_setup = c == cams;
    const int grey = is_setup ? 0 : 60 + static_cast<int>(120 * c / std::max<std::size_t>(cams, 1));
    const int thick = is_setup ? 3 : 1;
    std::optional<cv::Point> last;
    for (const VisibilityRow& r : rows) {
      const double d = is_setup ? r.setup_d_min_um : r.d_min_um[c];
      if (!std::isfinite(d)) {
        last.reset();
        continue;
      }
      const cv::Point p(px(r.z_mm), py(d));
      if (last) cv::line(m, *last, p, cv::Scalar(grey), thick, cv::LINE_AA);
      if (!is_setup) marker(m, p, static_cast<int>(c), grey);
      last = p;
    }
    const int ly = kTop + 20 + 24 * static_cast<int>(c);
    const int lx = kLeft + pw + 20;
    cv::line(m, {lx, ly}, {lx + 30, ly}, cv::Scalar(grey), thick, cv::LINE_AA);
    if (!is_setup) marker(m, {lx + 15, ly}, static_cast<int>(c), grey);
    text(m, is_setup ? std::string("set-up (max)") : setup.cameras[c].id, lx + 40, ly + 5);
  }

  Image out = Image::allocate(kWidth, kHeight, SampleType::u8);
  for (int y = 0; y < kHeight; ++y) std::memcpy(out.row<std::uint8_t>(y), m.ptr(y), kWidth);
  return out;
}

}  // namespace tomorig::optics
