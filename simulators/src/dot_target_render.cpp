// Dot plates drawn through a camera model: every pixel is supersampled; each sample's ray is
// met with the plate's first level, and where it shows no ink there, with the second.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <fmt/core.h>

#include "parallel.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/dot_target.h"
#include "tomorig/simulators/random.h"

namespace tomorig::sim {
namespace {

constexpr std::uint64_t kPlateNoiseStream = 0x706c617465ULL;  // "plate"

// Marker sizes in dot radii: clearly larger than a dot (the detector looks for >= 1.8 times
// a dot's area), small enough to keep clear of the neighbouring dots.
constexpr double kSquareHalf = 1.5;        // filled square: half side (area 2.9 dots)
constexpr double kTriangleRadius = 2.4;    // triangle: centroid to corner (area 2.4 dots)
constexpr double kFrameHalf = 2.2, kFrameLine = 0.5;  // hollow frame: centre line, line width

bool in_triangle(double x, double y, double r) {
  // Equilateral, centroid at 0, one corner at (r, 0): inside the three edges' half-planes.
  const double c = std::cos(2 * M_PI / 3), s = std::sin(2 * M_PI / 3);
  const double corners[3][2] = {{r, 0}, {r * c, r * s}, {r * c, -r * s}};
  for (int k = 0; k < 3; ++k) {
    const double* a = corners[k];
    const double* b = corners[(k + 1) % 3];
    if ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]) < 0) return false;
  }
  return true;
}

}  // namespace

void DotPlate::validate() const {
  if (!(spec.spacing_mm > 0) || !std::isfinite(spec.spacing_mm))
    throw bad_input(fmt::format("dot plate: spacing_mm = {} must be > 0", spec.spacing_mm));
  // The markers reach 3.4 dot radii from their site; the nearest other dot is a pitch away, or
  // pitch / sqrt(2) on a staggered plate.
  const double nearest = spec.lattice == calibration::DotLattice::staggered ? spec.spacing_mm / std::sqrt(2.0) : spec.spacing_mm;
  if (!(dot_radius_mm > 0) || 3.5 * dot_radius_mm > nearest)
    throw bad_input(fmt::format("dot plate: dot_radius_mm = {} must be > 0 and below {:.3g} mm (the markers must keep "
                                "clear of the dots {:.3g} mm away)",
                                dot_radius_mm, nearest / 3.5, nearest));
  if (half_extent < 1 || triangle_site < 0 || triangle_site > half_extent || samples < 1 || samples > 16)
    throw bad_input("dot plate: half_extent >= 1, 0 <= triangle_site <= half_extent and 1 <= samples <= 16");
}

double DotPlate::ink(double x, double y, int level) const {
  const double s = spec.spacing_mm, r = dot_radius_mm;
  const bool staggered = spec.lattice == calibration::DotLattice::staggered;
  if (level == 1) {
    if (!staggered) return 0;
    x -= 0.5 * s;
    y -= 0.5 * s;
  }
  const double fi = std::round(x / s), fj = std::round(y / s);
  if (std::abs(fi) > half_extent || std::abs(fj) > half_extent) return 0;
  const int i = static_cast<int>(fi), j = static_cast<int>(fj);
  const double dx = x - fi * s, dy = y - fj * s;
  if (level == 0) {
    if (i == 0 && j == 0) {
      if (filled_origin) return std::max(std::abs(dx), std::abs(dy)) < kSquareHalf * r ? 1 : 0;
      if (std::abs(std::max(std::abs(dx), std::abs(dy)) - kFrameHalf * r) < 0.5 * kFrameLine * r) return frame_contrast;
    }
    if (triangle_site > 0 && i == triangle_site && j == 0) return in_triangle(dx, dy, kTriangleRadius * r) ? 1 : 0;
  }
  return std::hypot(dx, dy) < r ? 1 : 0;
}

Image render_dot_plate(const calibration::CameraModel& camera, const DotPlate& plate, double z_mm, int width, int height) {
  return render_dot_plate([&](const Vec2d& pixel, double z) { return camera.back_project(pixel, z); }, plate, z_mm, width,
                          height);
}

Image render_dot_plate(const BackProjection& back_project, const DotPlate& plate, double z_mm, int width, int height) {
  plate.validate();
  const auto& o = plate.spec.origin_mm;
  const double z0 = z_mm + o.z, z1 = z0 + plate.spec.level_offset_mm;
  const bool two_levels = plate.spec.lattice == calibration::DotLattice::staggered;
  const int n = plate.samples;
  std::vector<float> cover(static_cast<std::size_t>(width) * height);
#pragma omp parallel for num_threads(detail::thread_count(0)) schedule(dynamic, 4)
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      double sum = 0;
      for (int a = 0; a < n; ++a)
        for (int b = 0; b < n; ++b) {
          const Vec2d px{u - 0.5 + (a + 0.5) / n, v - 0.5 + (b + 0.5) / n};
          const Vec3d p0 = back_project(px, z0);
          double ink = plate.ink(p0.x - o.x, p0.y - o.y, 0);
          if (ink == 0 && two_levels) {
            const Vec3d p1 = back_project(px, z1);
            ink = plate.ink(p1.x - o.x, p1.y - o.y, 1);
          }
          sum += ink;
        }
      cover[static_cast<std::size_t>(v) * width + u] = static_cast<float>(sum / (n * n));
    }
  const bool white = plate.spec.white_dots;
  const double paper = white ? plate.paper_counts : plate.ink_counts, ink = white ? plate.ink_counts : plate.paper_counts;
  std::mt19937_64 engine(derive_seed(plate.seed, {kPlateNoiseStream}));
  std::normal_distribution<double> gauss(0.0, 1.0);
  Image image = Image::allocate(width, height, SampleType::u16);
  for (int v = 0; v < height; ++v)
    for (int u = 0; u < width; ++u) {
      const double noise = plate.noise_counts > 0 ? plate.noise_counts * gauss(engine) : 0.0;
      const double value = paper + cover[static_cast<std::size_t>(v) * width + u] * (ink - paper) + noise;
      image.at<std::uint16_t>(u, v) = static_cast<std::uint16_t>(std::clamp(std::lround(value), 0L, 65535L));
    }
  return image;
}

}  // namespace tomorig::sim
