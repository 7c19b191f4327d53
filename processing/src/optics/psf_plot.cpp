#include "tomorig/processing/optics/psf_plot.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/core.h>
#include <opencv2/imgproc.hpp>

#include "optics/plot_helpers.h"
#include "tomorig/core/error.h"

namespace tomorig::optics {
namespace {

constexpr int kWidth = 900, kHeight = 560;
constexpr int kLeft = 80, kRight = 200, kTop = 40, kBottom = 60;  // margins; the legend sits right

}  // namespace

Image psf_plot(const PsfTable& table) {
  if (table.cameras.empty()) throw bad_input("PSF plot: the table has no cameras");
  double z0 = std::numeric_limits<double>::max(), z1 = -z0, lo = z0, hi = 0.0;
  for (const PsfTableCamera& c : table.cameras)
    for (std::size_t k = 0; k < c.z_mm.size(); ++k) {
      z0 = std::min(z0, c.z_mm[k]);
      z1 = std::max(z1, c.z_mm[k]);
      lo = std::min({lo, c.chi_um[k], c.chi_voxel_um[k]});
      hi = std::max({hi, c.chi_um[k], c.chi_voxel_um[k]});
    }
  if (z1 <= z0) {
    z0 -= 1.0;
    z1 += 1.0;
  }
  const double ystep = plot::tick_step(std::max(hi - lo, 1.0) * 1.3);
  const double ybottom = std::max(0.0, std::floor((lo - 0.1 * (hi - lo)) / ystep) * ystep);
  const double ytop = std::ceil((hi + 0.1 * (hi - lo) + 1e-9) / ystep) * ystep;

  cv::Mat m(kHeight, kWidth, CV_8UC1, cv::Scalar(255));
  const int pw = kWidth - kLeft - kRight, ph = kHeight - kTop - kBottom;
  const auto px = [&](double z) { return kLeft + static_cast<int>(std::lround((z - z0) / (z1 - z0) * pw)); };
  const auto py = [&](double chi) {
    return kTop + ph - static_cast<int>(std::lround((std::clamp(chi, ybottom, ytop) - ybottom) / (ytop - ybottom) * ph));
  };
  for (double v = ybottom; v <= ytop + 1e-9; v += ystep) {
    cv::line(m, {kLeft, py(v)}, {kLeft + pw, py(v)}, cv::Scalar(225), 1);
    plot::text(m, fmt::format("{:g}", v), kLeft - 45, py(v) + 5);
  }
  const double zstep = plot::tick_step(z1 - z0);
  for (double z = std::ceil(z0 / zstep) * zstep; z <= z1 + 1e-9; z += zstep) {
    cv::line(m, {px(z), kTop}, {px(z), kTop + ph}, cv::Scalar(225), 1);
    plot::text(m, fmt::format("{:g}", std::abs(z) < 1e-12 ? 0.0 : z), px(z) - 12, kTop + ph + 20);
  }
  cv::rectangle(m, {kLeft, kTop}, {kLeft + pw, kTop + ph}, cv::Scalar(0), 1);
  plot::text(m, "z [mm]", kLeft + pw / 2 - 25, kHeight - 15, 0.55);
  plot::text(m, "chi [um]", 5, kTop - 12, 0.55);
  plot::text(m, fmt::format("PSF half-width from chessboard edges ({:.1f} voxel/mm, spread along {})", 1.0 / table.voxel_mm,
                            table.axis),
             kLeft + 20, 25, 0.55);

  const std::size_t cams = table.cameras.size();
  for (std::size_t c = 0; c < cams; ++c) {
    const PsfTableCamera& cam = table.cameras[c];
    const int grey = 40 + static_cast<int>(140 * c / std::max<std::size_t>(cams, 1));
    for (std::size_t k = 0; k < cam.z_mm.size(); ++k) {
      const cv::Point p(px(cam.z_mm[k]), py(cam.chi_um[k])), q(px(cam.z_mm[k]), py(cam.chi_voxel_um[k]));
      plot::marker(m, p, static_cast<int>(c), grey);
      cv::circle(m, q, 1, cv::Scalar(grey), cv::FILLED);
      if (k > 0) {
        cv::line(m, {px(cam.z_mm[k - 1]), py(cam.chi_um[k - 1])}, p, cv::Scalar(grey), 2, cv::LINE_AA);
        cv::line(m, {px(cam.z_mm[k - 1]), py(cam.chi_voxel_um[k - 1])}, q, cv::Scalar(grey), 1, cv::LINE_AA);
      }
    }
    const int ly = kTop + 20 + 24 * static_cast<int>(c), lx = kLeft + pw + 20;
    cv::line(m, {lx, ly}, {lx + 30, ly}, cv::Scalar(grey), 2, cv::LINE_AA);
    plot::marker(m, {lx + 15, ly}, static_cast<int>(c), grey);
    plot::text(m, cam.id, lx + 40, ly + 5);
  }
  const int ly = kTop + 30 + 24 * static_cast<int>(cams), lx = kLeft + pw + 20;
  plot::text(m, "thick: camera PSF", lx, ly);
  plot::text(m, "thin: in the voxel", lx, ly + 20);
  plot::text(m, "planes (measured)", lx, ly + 38);

  Image out = Image::allocate(kWidth, kHeight, SampleType::u8);
  for (int y = 0; y < kHeight; ++y) std::memcpy(out.row<std::uint8_t>(y), m.ptr(y), kWidth);
  return out;
}

}  // namespace tomorig::optics
