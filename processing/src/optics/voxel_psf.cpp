#include "tomorig/processing/optics/voxel_psf.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/optics/edge_psf.h"

namespace tomorig::optics {
namespace {

// Bilinear interpolation of a pixel image at a sub-pixel position inside it.
double bilinear(const Image& image, double u, double v) {
  const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, image.width() - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, image.height() - 2);
  const double fx = u - x0, fy = v - y0;
  return (1 - fy) * ((1 - fx) * image.value(x0, y0) + fx * image.value(x0 + 1, y0)) +
         fy * ((1 - fx) * image.value(x0, y0 + 1) + fx * image.value(x0 + 1, y0 + 1));
}

double percentile(std::vector<double>& v, double p) {
  const auto k = static_cast<std::ptrdiff_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

// The transpose of an f32 image: edges along x become the column edges edge_psf.h measures.
Image transposed(const Image& in) {
  Image out = Image::allocate(in.height(), in.width(), SampleType::f32);
  for (int y = 0; y < in.height(); ++y) {
    const float* row = in.row<float>(y);
    for (int x = 0; x < in.width(); ++x) out.at<float>(y, x) = row[x];
  }
  return out;
}

// The board's square size in pixels of `image` (rows run across the measured edges): the median
// distance between neighbouring crossings of each row's mid level (between its 5th and 95th
// percentiles). 0 if there are too few.
double square_size(const Image& image) {
  std::vector<double> gaps, row(static_cast<std::size_t>(image.width()));
  for (int y = 0; y < image.height(); y += 2) {
    for (int x = 0; x < image.width(); ++x) row[static_cast<std::size_t>(x)] = image.value(x, y);
    std::vector<double> sorted = row;
    const double dark = percentile(sorted, 0.05), light = percentile(sorted, 0.95);
    if (!(light > 0) || (light - dark) / light < 0.2) continue;  // no board across this row
    const double mid = 0.5 * (dark + light);
    double last = -1;
    for (std::size_t x = 0; x + 1 < row.size(); ++x) {
      const double a = row[x] - mid, b = row[x + 1] - mid;
      if ((a < 0) == (b < 0) || a == b) continue;
      const double at = static_cast<double>(x) + a / (a - b);
      if (last >= 0 && at - last > 2.0) gaps.push_back(at - last);  // noise re-crossings are closer
      last = at;
    }
  }
  if (gaps.size() < 8) return 0;
  return percentile(gaps, 0.5);
}

}  // namespace

void VoxelPlane::validate() const {
  if (!std::isfinite(x0_mm) || !std::isfinite(y0_mm) || !std::isfinite(z_mm))
    throw bad_input("voxel plane: x0, y0 and z must be finite");
  if (!(voxel_mm > 0) || !std::isfinite(voxel_mm))
    throw bad_input(fmt::format("voxel plane: voxel size {} mm must be > 0", voxel_mm));
  if (nx < 32 || ny < 32 || nx > 20000 || ny > 20000)
    throw bad_input(fmt::format("voxel plane: {} x {} voxels: give 32 to 20000 voxels a side", nx, ny));
}

double VoxelPsf::sigma_px() const { return std::sqrt(std::max(0.25 * chi_px * chi_px - 1.0 / 12.0, 1e-6)); }

Image back_project_plane(const Image& image, const calibration::CameraModel& camera, const VoxelPlane& plane) {
  plane.validate();
  if (image.empty() || image.width() < 2 || image.height() < 2) throw bad_input("back-projection: the image is empty");
  Image out = Image::allocate(plane.nx, plane.ny, SampleType::f32);
  for (int j = 0; j < plane.ny; ++j) {
    float* row = out.row<float>(j);
    for (int i = 0; i < plane.nx; ++i) {
      const Vec3d p{plane.x0_mm + i * plane.voxel_mm, plane.y0_mm + j * plane.voxel_mm, plane.z_mm};
      const Vec2d uv = camera.project(p);
      if (!(uv.x >= 0 && uv.y >= 0 && uv.x <= image.width() - 1 && uv.y <= image.height() - 1))
        throw bad_input(fmt::format("back-projection: voxel ({:.3f}, {:.3f}, {:.3f}) mm is imaged at ({:.1f}, {:.1f}) px, "
                                    "outside the {} x {} px image: choose a smaller plane (--grid)",
                                    p.x, p.y, p.z, uv.x, uv.y, image.width(), image.height()));
      row[i] = static_cast<float>(bilinear(image, uv.x, uv.y));
    }
  }
  return out;
}

Image flat_field_chessboard(const Image& plane_image, double square_px) {
  const int w = plane_image.width(), h = plane_image.height();
  if (!(square_px >= 4) || w < 2 * square_px || h < 2 * square_px)
    throw bad_input(fmt::format("flat field: a {} x {} image holds less than 2 x 2 squares of {:.1f} px", w, h, square_px));
  // Levels on a grid about a square apart, each from a window 2.5 squares wide (both colours).
  const int gx = std::max(1, static_cast<int>(std::lround(w / square_px))), gy = std::max(1, static_cast<int>(std::lround(h / square_px)));
  const int reach = static_cast<int>(std::ceil(1.25 * square_px));
  std::vector<double> dark(static_cast<std::size_t>(gx * gy)), bright(dark.size()), values;
  for (int ty = 0; ty < gy; ++ty)
    for (int tx = 0; tx < gx; ++tx) {
      const int cx = static_cast<int>((tx + 0.5) * w / gx), cy = static_cast<int>((ty + 0.5) * h / gy);
      const int x0 = std::clamp(cx - reach, 0, std::max(0, w - 2 * reach)), y0 = std::clamp(cy - reach, 0, std::max(0, h - 2 * reach));
      values.clear();
      for (int y = y0; y < std::min(h, y0 + 2 * reach); y += 2)
        for (int x = x0; x < std::min(w, x0 + 2 * reach); x += 2) values.push_back(plane_image.value(x, y));
      const double lo = percentile(values, 0.10), hi = percentile(values, 0.90);
      if (!(hi > 0) || !(hi - lo > 0.05 * hi))
        throw bad_input(fmt::format("flat field: around ({}, {}) the plane has no chessboard contrast (10th / 90th "
                                    "percentile {:.4g} / {:.4g}): is the board in the plane?",
                                    cx, cy, lo, hi));
      dark[static_cast<std::size_t>(ty * gx + tx)] = lo;
      bright[static_cast<std::size_t>(ty * gx + tx)] = hi;
    }
  // Bilinear between the grid points, constant beyond the outer ones.
  const auto level = [&](const std::vector<double>& grid, int x, int y) {
    const double fxg = std::clamp((x + 0.5) * gx / w - 0.5, 0.0, gx - 1.0);
    const double fyg = std::clamp((y + 0.5) * gy / h - 0.5, 0.0, gy - 1.0);
    const int x0 = static_cast<int>(fxg), y0 = static_cast<int>(fyg);
    const int x1 = std::min(x0 + 1, gx - 1), y1 = std::min(y0 + 1, gy - 1);
    const double fx = fxg - x0, fy = fyg - y0;
    const auto g = [&](int a, int b) { return grid[static_cast<std::size_t>(b * gx + a)]; };
    return (1 - fy) * ((1 - fx) * g(x0, y0) + fx * g(x1, y0)) + fy * ((1 - fx) * g(x0, y1) + fx * g(x1, y1));
  };
  Image out = Image::allocate(w, h, SampleType::f32);
  for (int y = 0; y < h; ++y) {
    float* row = out.row<float>(y);
    for (int x = 0; x < w; ++x) {
      const double d = level(dark, x, y), b = level(bright, x, y);
      row[x] = static_cast<float>((plane_image.value(x, y) - d) / (b - d));
    }
  }
  return out;
}

VoxelPlane common_view_plane(const std::vector<const calibration::CameraModel*>& cameras,
                             const std::vector<ImageSize>& sizes, const std::vector<double>& z_mm) {
  if (cameras.empty() || cameras.size() != sizes.size() || z_mm.empty())
    throw bad_input("voxel plane: needs the cameras, their image sizes and at least one depth");
  const auto [zlo, zhi] = std::minmax_element(z_mm.begin(), z_mm.end());
  const double zmid = 0.5 * (*zlo + *zhi);
  const auto seen = [&](double x, double y) {
    for (std::size_t c = 0; c < cameras.size(); ++c)
      for (double z : z_mm) {
        const Vec2d uv = cameras[c]->project({x, y, z});
        if (!(uv.x >= 1 && uv.y >= 1 && uv.x <= sizes[c].width - 2 && uv.y <= sizes[c].height - 2)) return false;
      }
    return true;
  };
  // One pixel in object space: 1 / the largest singular value of the image Jacobian.
  double voxel = 1e9;
  for (const calibration::CameraModel* cam : cameras) {
    const double h = 0.01;
    const Vec2d a = cam->project({h, 0, zmid}), b = cam->project({-h, 0, zmid});
    const Vec2d c = cam->project({0, h, zmid}), d = cam->project({0, -h, zmid});
    const double ux = (a.x - b.x) / (2 * h), vx = (a.y - b.y) / (2 * h), uy = (c.x - d.x) / (2 * h), vy = (c.y - d.y) / (2 * h);
    const double m00 = ux * ux + vx * vx, m01 = ux * uy + vx * vy, m11 = uy * uy + vy * vy;
    const double largest = std::sqrt(0.5 * (m00 + m11) + std::sqrt(0.25 * (m00 - m11) * (m00 - m11) + m01 * m01));
    if (largest > 0 && std::isfinite(largest)) voxel = std::min(voxel, 1.0 / largest);
  }
  if (!(voxel < 1e9)) throw bad_input("voxel plane: a camera does not image the z axis");
  // Shrink a square until its border is seen by every camera at every depth.
  double half = 0.0;
  for (double h = 50.0; h > 20 * voxel; h *= 0.95) {
    bool ok = true;
    for (int i = 0; i <= 8 && ok; ++i) {
      const double t = -h + i * h / 4.0;
      ok = seen(t, -h) && seen(t, h) && seen(-h, t) && seen(h, t);
    }
    if (ok) {
      half = 0.9 * h;
      break;
    }
  }
  if (half == 0.0)
    throw bad_input("voxel plane: the cameras share no view of the z axis at these depths: give the plane (--grid)");
  const int n = static_cast<int>(2.0 * half / voxel);
  return {-0.5 * (n - 1) * voxel, -0.5 * (n - 1) * voxel, 0.0, voxel, n, n};
}

VoxelPsf measure_voxel_psf(const Image& image, const calibration::CameraModel& camera, const VoxelPlane& plane,
                           SpreadAxis axis) {
  // edge_psf.h measures edges running down the columns: the spread along y needs the board
  // lines along x there, i.e. the transposed plane.
  const Image plane_image = back_project_plane(image, camera, plane);
  const Image raw = axis == SpreadAxis::y ? transposed(plane_image) : plane_image;
  VoxelPsf out;
  out.square_voxels = square_size(raw);
  if (!(out.square_voxels >= 12))
    throw bad_input(fmt::format("voxel PSF: no chessboard (contrast >= 20 %, squares >= 12 voxels) in the {} x {} voxel plane at z = "
                                "{} mm (found {:.1f}): use smaller voxels or a larger plane",
                                plane.nx, plane.ny, plane.z_mm, out.square_voxels));
  const Image across = flat_field_chessboard(raw, out.square_voxels);
  EdgeSpreadOptions o;
  // Samples reach 0.4 of a square either side (the next edge is a square away), rows within a
  // quarter square of a corner are left out (the crossing edge spreads there).
  o.half_width_px = std::clamp(static_cast<int>(0.4 * out.square_voxels), 5, 80);
  o.end_margin_rows = std::max(3, static_cast<int>(0.25 * out.square_voxels));
  o.min_rows = std::max(6, static_cast<int>(0.3 * out.square_voxels));
  o.pool_edges = true;  // flat-fielded: one level for all edges
  const EdgePsf edges = measure_edge_psf(across, o);
  out.edges = static_cast<int>(edges.edges.size());
  std::vector<double> slopes;
  for (const EdgeMeasurement& e : edges.edges) slopes.push_back(e.slope);
  out.rms_residual = edges.rms_residual;
  const double slope = percentile(slopes, 0.5);
  out.chi_voxel_um = edges.chi_px * plane.voxel_mm * 1000.0;

  // The image Jacobian at the plane's centre (pixels per mm along x and y).
  const Vec3d c{plane.x0_mm + 0.5 * (plane.nx - 1) * plane.voxel_mm, plane.y0_mm + 0.5 * (plane.ny - 1) * plane.voxel_mm,
                plane.z_mm};
  const double step = plane.voxel_mm;
  const auto derivative = [&](const Vec3d& d) {
    const Vec2d a = camera.project(c + d), b = camera.project(c - d);
    return Vec2d{(a.x - b.x) * 0.5 / step, (a.y - b.y) * 0.5 / step};
  };
  const Vec2d ux = derivative({step, 0, 0}), uy = derivative({0, step, 0});
  // M = J^T J; its inverse maps an isotropic image spread into the plane.
  const double m00 = ux.x * ux.x + ux.y * ux.y, m01 = ux.x * uy.x + ux.y * uy.y, m11 = uy.x * uy.x + uy.y * uy.y;
  const double det = m00 * m11 - m01 * m01;
  if (!(det > 0)) throw bad_input(fmt::format("voxel PSF: the camera sees the plane z = {} mm edge-on", plane.z_mm));
  // The plane direction across the measured edges: an edge u = a + b v of `across` runs along
  // (b, 1) in its (column, row) axes.
  double ex = 0, ey = 0;
  if (axis == SpreadAxis::y) {  // columns are y, rows x: the edge runs along (x, y) = (1, b)
    ex = -slope;
    ey = 1.0;
  } else {  // columns x, rows y: the edge runs along (b, 1)
    ex = 1.0;
    ey = -slope;
  }
  const double n = std::hypot(ex, ey);
  ex /= n;
  ey /= n;
  // q = e^T M^-1 e: mm^2 in the plane per px^2 of an isotropic image spread, along e.
  const double q = (m11 * ex * ex - 2.0 * m01 * ex * ey + m00 * ey * ey) / det;
  // Bilinear interpolation averaged over the sub-pixel phases spreads like a tent of variance
  // 1/6 px^2 in any direction of the image: what the camera's own PSF lacks.
  const double sigma_plane_mm = 0.5 * edges.chi_px * plane.voxel_mm;
  const double sigma_image_px2 = sigma_plane_mm * sigma_plane_mm / q - 1.0 / 6.0;
  out.chi_px = 2.0 * std::sqrt(std::max(sigma_image_px2, 1e-6));
  // One pixel in object space: the plane's least stretched direction (parallel to the sensor),
  // 1 / the largest singular value of J.
  const double largest = std::sqrt(0.5 * (m00 + m11) + std::sqrt(0.25 * (m00 - m11) * (m00 - m11) + m01 * m01));
  out.object_pixel_um = 1000.0 / largest;
  out.chi_um = out.chi_px * out.object_pixel_um;
  return out;
}

}  // namespace tomorig::optics
