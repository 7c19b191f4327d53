// Rendering one calib-thesis view: exact-enough area integration of the chessboard over each
// pixel, Gaussian optical blur, then the sensor model (shot + read noise, 16-bit).
#include <algorithm>
#include <cmath>
#include <vector>

#include "parallel.h"
#include "tomorig/simulators/calibration_target.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/sensor.h"

namespace tomorig::sim {

namespace {

constexpr std::uint64_t kTargetNoiseStream = 0x746172676574ULL;  // "target"

// Board coordinates in units of squares: inner corner (i, j) at (i, j). The printed squares
// cover [-1, nx] x [-1, ny]; outside is background.
struct Board {
  int nx, ny;
  float light, dark, background;
  // Region id: a cell index, or -1 for the background (equal ids mean equal grey).
  long region(double bx, double by) const {
    if (bx < -1 || by < -1 || bx >= nx || by >= ny) return -1;
    const long cx = static_cast<long>(std::floor(bx)) + 1, cy = static_cast<long>(std::floor(by)) + 1;
    return cy * (nx + 2) + cx;
  }
  float grey(double bx, double by) const {
    if (bx < -1 || by < -1 || bx >= nx || by >= ny) return background;
    const long cx = static_cast<long>(std::floor(bx)), cy = static_cast<long>(std::floor(by));
    return ((cx + cy) & 1) ? light : dark;
  }
};

// A Fibonacci lattice of 144 points in the unit square: every row and column of a 144 x 144
// grid holds exactly one point, so a straight edge across the pixel is located to ~1/300 px
// whatever its direction (a regular 12 x 12 grid would round axis-aligned edges to 1/24 px).
struct Lattice144 {
  double x[144], y[144];
  Lattice144() {
    for (int k = 0; k < 144; ++k) {
      x[k] = (k + 0.5) / 144.0;
      y[k] = ((k * 89) % 144 + 0.5) / 144.0;
    }
  }
};

void gaussian_blur(std::vector<float>& img, int w, int h, double sigma, int threads) {
  if (sigma < 0.05) return;
  const int r = static_cast<int>(std::ceil(3.5 * sigma));
  std::vector<float> kernel(2 * r + 1);
  double sum = 0;
  for (int k = -r; k <= r; ++k) sum += kernel[k + r] = static_cast<float>(std::exp(-0.5 * k * k / (sigma * sigma)));
  for (float& v : kernel) v = static_cast<float>(v / sum);
  std::vector<float> tmp(img.size());
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double acc = 0;
      for (int k = -r; k <= r; ++k) acc += kernel[k + r] * img[static_cast<std::size_t>(y) * w + std::clamp(x + k, 0, w - 1)];
      tmp[static_cast<std::size_t>(y) * w + x] = static_cast<float>(acc);
    }
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double acc = 0;
      for (int k = -r; k <= r; ++k) acc += kernel[k + r] * tmp[static_cast<std::size_t>(std::clamp(y + k, 0, h - 1)) * w + x];
      img[static_cast<std::size_t>(y) * w + x] = static_cast<float>(acc);
    }
}

}  // namespace

Image render_target_view(const CalibTargetCase& c, std::size_t camera, std::size_t plane) {
  const TargetCamera& cam = c.cameras.at(camera);
  const TargetPlane& pl = c.planes.at(plane);
  const CalibTargetOptions& o = c.options;
  const int w = cam.width, h = cam.height;
  const int threads = detail::thread_count(0);
  const Board board{c.board.inner_corners_x, c.board.inner_corners_y, static_cast<float>(o.light_counts),
                    static_cast<float>(o.dark_counts), static_cast<float>(o.background_counts)};
  const double s = c.board.square_mm;
  const double z = pl.z_nominal_mm + pl.offset_mm.z;

  // Board coordinates of every pixel corner ((W+1) x (H+1)); within one pixel they are
  // interpolated bilinearly (the mapping is smooth on that scale).
  const std::size_t cw = static_cast<std::size_t>(w) + 1;
  std::vector<double> bx(cw * (h + 1)), by(cw * (h + 1));
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y <= h; ++y)
    for (int x = 0; x <= w; ++x) {
      const Vec3d p = cam.back_project({x - 0.5, y - 0.5}, z);
      bx[y * cw + x] = (p.x - pl.offset_mm.x) / s;
      by[y * cw + x] = (p.y - pl.offset_mm.y) / s;
    }

  static const Lattice144 lattice;
  std::vector<float> signal(static_cast<std::size_t>(w) * h);
#pragma omp parallel for num_threads(threads) schedule(static)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i00 = y * cw + x, i10 = i00 + 1, i01 = i00 + cw, i11 = i01 + 1;
      const long r = board.region(bx[i00], by[i00]);
      float value;
      if (board.region(bx[i10], by[i10]) == r && board.region(bx[i01], by[i01]) == r &&
          board.region(bx[i11], by[i11]) == r) {
        value = board.grey(bx[i00], by[i00]);
      } else {
        double acc = 0;
        for (int k = 0; k < 144; ++k) {
          const double fx = lattice.x[k], fy = lattice.y[k];
          const double u = (1 - fy) * ((1 - fx) * bx[i00] + fx * bx[i10]) + fy * ((1 - fx) * bx[i01] + fx * bx[i11]);
          const double v = (1 - fy) * ((1 - fx) * by[i00] + fx * by[i10]) + fy * ((1 - fx) * by[i01] + fx * by[i11]);
          acc += board.grey(u, v);
        }
        value = static_cast<float>(acc / 144);
      }
      signal[static_cast<std::size_t>(y) * w + x] = value;
    }
  gaussian_blur(signal, w, h, o.blur_sigma_px, threads);

  Image f = Image::allocate(w, h, SampleType::f32);
  for (int y = 0; y < h; ++y) std::copy_n(&signal[static_cast<std::size_t>(y) * w], w, f.row<float>(y));
  SensorOptions sensor;
  sensor.bit_depth = 16;
  sensor.noise = o.noise;
  sensor.gain_counts_per_e = 1.0;
  sensor.read_noise_e = 5.0;
  return digitise(f, sensor, derive_seed(o.seed, {kTargetNoiseStream, camera, plane}));
}

}  // namespace tomorig::sim
