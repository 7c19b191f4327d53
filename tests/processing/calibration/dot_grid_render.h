#pragma once
// Renders dot-grid target images through a known camera, for the detection tests: dots of
// radius `dot_radius_mm` on a square lattice of `spacing_mm`, a square frame round the origin
// dot, anti-aliased by supersampling each pixel against the exact target (so dots appear as
// the camera would see them, perspective included).
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace dot_grid_test {

using tomorig::Image;
using tomorig::Vec2d;
using tomorig::Vec3d;

struct TargetDrawing {
  double spacing_mm = 2.0;
  double dot_radius_mm = 0.25;
  int half_extent = 30;               // dots at |i|, |j| <= half_extent
  double marker_half_mm = 0.55;       // the frame's centre line, from the origin
  double marker_line_mm = 0.12;
  double marker_contrast = 1.0;           // frame ink relative to the dots' (fluidimage: 1/30)
  bool white_dots = true;
  std::set<std::pair<int, int>> missing;  // lattice sites left blank
  std::vector<Vec2d> extra_dots_mm;       // stray dots (world x, y)
  Vec2d offset_mm;                        // target origin position on the plane
};

// Ink at a world point of the plane: 1 on a dot, marker_contrast on the frame, else 0.
inline double inked(const TargetDrawing& t, double x, double y) {
  x -= t.offset_mm.x;
  y -= t.offset_mm.y;
  const double i = std::round(x / t.spacing_mm), j = std::round(y / t.spacing_mm);
  if (std::abs(i) <= t.half_extent && std::abs(j) <= t.half_extent &&
      !t.missing.count({static_cast<int>(i), static_cast<int>(j)}) &&
      std::hypot(x - i * t.spacing_mm, y - j * t.spacing_mm) < t.dot_radius_mm)
    return 1;
  for (const Vec2d& e : t.extra_dots_mm)
    if (std::hypot(x - e.x, y - e.y) < t.dot_radius_mm) return 1;
  const double box = std::max(std::abs(x), std::abs(y));
  return std::abs(box - t.marker_half_mm) < t.marker_line_mm / 2 ? t.marker_contrast : 0;
}

// A 16-bit image of the target on plane z seen by `camera`; background 200 (black-dot targets:
// ink 200 on 3000), ink 3000, 4 x 4 samples per pixel, plus Gaussian noise of `noise` counts.
inline Image render_target(const tomorig::calibration::CameraModel& camera, const TargetDrawing& t, double z, int width,
                           int height, double noise = 0, unsigned seed = 1) {
  constexpr int kSub = 4;
  Image image = Image::allocate(width, height, tomorig::SampleType::u16);
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double paper = t.white_dots ? 200 : 3000, ink = t.white_dots ? 3000 : 200;
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      double hits = 0;
      for (int a = 0; a < kSub; ++a)
        for (int b = 0; b < kSub; ++b) {
          const Vec2d px{u - 0.5 + (a + 0.5) / kSub, v - 0.5 + (b + 0.5) / kSub};
          const Vec3d w = camera.back_project(px, z);
          hits += inked(t, w.x, w.y);
        }
      const double f = hits / (kSub * kSub);
      const double value = paper + f * (ink - paper) + noise * gauss(rng);
      image.at<std::uint16_t>(u, v) = static_cast<std::uint16_t>(std::clamp(std::lround(value), 0L, 65535L));
    }
  return image;
}

// A pinhole camera at `distance_mm` from the world origin, turned by yaw (about y), then
// pitch (about x), then roll (about the optical axis), degrees.
inline tomorig::calibration::PinholeCamera oblique_camera(double yaw_deg, double pitch_deg, double roll_deg,
                                                          double px_per_mm_at_origin, double distance_mm, int width,
                                                          int height) {
  const double d2r = M_PI / 180;
  const double cy = std::cos(yaw_deg * d2r), sy = std::sin(yaw_deg * d2r);
  const double cp = std::cos(pitch_deg * d2r), sp = std::sin(pitch_deg * d2r);
  const double cr = std::cos(roll_deg * d2r), sr = std::sin(roll_deg * d2r);
  auto mul = [](const tomorig::Mat3d& a, const tomorig::Mat3d& b) {
    tomorig::Mat3d c{};
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k)
        for (int m = 0; m < 3; ++m) c[3 * r + k] += a[3 * r + m] * b[3 * m + k];
    return c;
  };
  const tomorig::Mat3d yaw{cy, 0, -sy, 0, 1, 0, sy, 0, cy};
  const tomorig::Mat3d pitch{1, 0, 0, 0, cp, sp, 0, -sp, cp};
  const tomorig::Mat3d roll{cr, sr, 0, -sr, cr, 0, 0, 0, 1};
  tomorig::calibration::PinholeParameters p;
  p.R = mul(roll, mul(pitch, yaw));
  p.t = {0, 0, distance_mm};
  p.fx = p.fy = px_per_mm_at_origin * distance_mm;
  p.cx = (width - 1) / 2.0;
  p.cy = (height - 1) / 2.0;
  return tomorig::calibration::PinholeCamera(p);
}

}  // namespace dot_grid_test
