#pragma once
// Ground-truth calibration points for the camera-model tests: a known PinholeCamera (the
// tpiv-thesis geometry: f = 100 mm, 7.4 um pixels, 263.16 mm away, 512 px), optionally with a
// known radial lens distortion applied in the image and Gaussian noise on the pixels.
#include <cmath>
#include <random>
#include <vector>

#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace calib_test {

using tomorig::Vec2d;
using tomorig::Vec3d;
using tomorig::calibration::PinholeCamera;
using tomorig::calibration::PointCorrespondence;

constexpr int kImageSize = 512;

inline PinholeCamera thesis_camera(double yaw_deg) {
  return PinholeCamera::yawed(yaw_deg, 100.0, 7.4, 263.16, kImageSize, kImageSize);
}

// Radial distortion about the image centre: u_d = c + (u - c)(1 + k r^2 / 256^2). k = 7e-4
// moves the image corners by ~0.5 px, a little more than the lens of thesis Sect. 6.3.
struct Truth {
  PinholeCamera camera = thesis_camera(14);
  double radial_k = 0;

  Vec2d image_of(const Vec3d& world) const {
    const Vec2d u = camera.project(world);
    const double c = (kImageSize - 1) / 2.0;
    const double dx = u.x - c, dy = u.y - c;
    const double f = 1 + radial_k * (dx * dx + dy * dy) / (256.0 * 256.0);
    return {c + dx * f, c + dy * f};
  }
};

// An n x n grid spanning +-half_mm on each plane z, seen through `truth`, with pixel noise.
inline std::vector<PointCorrespondence> grid_points(const Truth& truth, const std::vector<double>& planes, int n,
                                                    double half_mm = 4.0, double noise_px = 0, unsigned seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_px > 0 ? noise_px : 1.0);
  std::vector<PointCorrespondence> out;
  for (double z : planes)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const Vec3d w{-half_mm + 2 * half_mm * i / (n - 1), -half_mm + 2 * half_mm * j / (n - 1), z};
        Vec2d u = truth.image_of(w);
        if (noise_px > 0) u = {u.x + noise(rng), u.y + noise(rng)};
        out.push_back({w, u});
      }
  return out;
}

// Held-out points: random positions inside the calibrated volume (not on the grid planes).
inline std::vector<Vec3d> random_points(int count, double half_mm, double z_lo, double z_hi, unsigned seed = 99) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> xy(-half_mm, half_mm), z(z_lo, z_hi);
  std::vector<Vec3d> out;
  for (int k = 0; k < count; ++k) out.push_back({xy(rng), xy(rng), z(rng)});
  return out;
}

inline const std::vector<double> kFivePlanes{-2.0, -1.0, 0.0, 1.0, 2.0};

}  // namespace calib_test
