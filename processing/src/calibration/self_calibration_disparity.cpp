// Sub-volume disparities (Wieneke 2008, Sect. 2): per camera and sub-volume, the disparities
// of all candidate particles are accumulated into a disparity map; true particles agree and
// form its peak, ghost matches scatter over the search disc. The peak is refined by the mean
// of the disparities within a small window around it.
#include <algorithm>
#include <cmath>

#include "self_calibration_internal.h"

namespace tomorig::calibration::selfcal {
namespace {

constexpr double kMapCellPx = 0.1;
constexpr int kMeanShiftSteps = 5;

// The peak of the disparity map of `members` (match indices) for one camera.
Vec2d map_peak(const Matches& matches, const std::vector<std::size_t>& members, std::size_t camera, double radius_px,
               std::vector<double>& map) {
  const int n = std::max(1, static_cast<int>(std::ceil(2 * radius_px / kMapCellPx)));
  map.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(n), 0.0);
  const auto cell = [&](double d) { return std::clamp(static_cast<int>(std::floor((d + radius_px) / kMapCellPx)), 0, n - 1); };
  for (const std::size_t m : members) {
    const Vec2d& d = matches.disparity_of(m, camera);
    map[static_cast<std::size_t>(cell(d.x) + n * cell(d.y))] += matches.weight[m];
  }
  // The map's maximum after a 3 x 3 box sum, so one cell's chance pile-up does not win.
  double best = -1;
  int best_x = n / 2, best_y = n / 2;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      double sum = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx >= 0 && yy >= 0 && xx < n && yy < n) sum += map[static_cast<std::size_t>(xx + n * yy)];
        }
      if (sum > best) {
        best = sum;
        best_x = x;
        best_y = y;
      }
    }
  return {(best_x + 0.5) * kMapCellPx - radius_px, (best_y + 0.5) * kMapCellPx - radius_px};
}

DisparityFigures figures(const CameraModel& model, const std::vector<SubvolumeDisparity>& maps,
                         const SubvolumeGrid& grid, int layer) {
  DisparityFigures f;
  double sum_px = 0, sum_um = 0;
  for (int i = 0; i < grid.count(); ++i) {
    const SubvolumeDisparity& s = maps[static_cast<std::size_t>(i)];
    if (!s.valid || (layer >= 0 && grid.layer(i) != layer)) continue;
    const double px = std::hypot(s.disparity.x, s.disparity.y);
    const Vec3d centre = grid.centre(i);
    const Vec2d pixel = model.project(centre);
    const Vec3d shifted = model.back_project({pixel.x - s.disparity.x, pixel.y - s.disparity.y}, centre.z);
    const Vec3d here = model.back_project(pixel, centre.z);
    sum_px += px;
    sum_um += (shifted - here).norm() * 1000.0;
    f.max_px = std::max(f.max_px, px);
    ++f.subvolumes;
  }
  if (f.subvolumes > 0) {
    f.mean_px = sum_px / f.subvolumes;
    f.mean_um = sum_um / f.subvolumes;
  }
  return f;
}

}  // namespace

int SubvolumeGrid::index_of(const Vec3d& p) const {
  const auto axis = [](double v, double lo, double hi, int n) {
    if (v < lo || v > hi) return -1;
    return std::min(n - 1, static_cast<int>((v - lo) / (hi - lo) * n));
  };
  const int i = axis(p.x, bounds.min.x, bounds.max.x, nx);
  const int j = axis(p.y, bounds.min.y, bounds.max.y, ny);
  const int k = axis(p.z, bounds.min.z, bounds.max.z, nz);
  if (i < 0 || j < 0 || k < 0) return -1;
  return i + nx * (j + ny * k);
}

Vec3d SubvolumeGrid::centre(int index) const {
  const int i = index % nx, j = (index / nx) % ny, k = index / (nx * ny);
  const Vec3d size = bounds.max - bounds.min;
  return {bounds.min.x + (i + 0.5) * size.x / nx, bounds.min.y + (j + 0.5) * size.y / ny, layer_z(k)};
}

double SubvolumeGrid::layer_z(int k) const { return bounds.min.z + (k + 0.5) * (bounds.max.z - bounds.min.z) / nz; }

DisparityMaps measure_disparities(const Matches& matches, const SubvolumeGrid& grid, double radius_px,
                                  const SelfCalibrationOptions& options) {
  std::vector<std::vector<std::size_t>> members(static_cast<std::size_t>(grid.count()));
  for (std::size_t m = 0; m < matches.size(); ++m) {
    const int s = grid.index_of(matches.world[m]);
    if (s >= 0) members[static_cast<std::size_t>(s)].push_back(m);
  }
  DisparityMaps maps(matches.cameras, std::vector<SubvolumeDisparity>(static_cast<std::size_t>(grid.count())));
  std::vector<double> map;
  const double window2 = options.peak_window_px * options.peak_window_px;
  const std::size_t cameras = matches.cameras;
  std::vector<Vec2d> estimate(cameras), sum(cameras);
  for (std::size_t s = 0; s < members.size(); ++s) {
    if (members[s].empty()) continue;
    // Start from each camera's own disparity-map peak, then shift jointly: a match counts
    // only if its disparities are near the estimate in every camera at once. True particles
    // of a sub-volume share one joint disparity; ghosts, built from unrelated peaks, rarely
    // come near it in all cameras, so they neither pull the estimate nor count as support.
    for (std::size_t c = 0; c < cameras; ++c) estimate[c] = map_peak(matches, members[s], c, radius_px, map);
    double support = 0;
    Vec3d world;
    for (int step = 0; step < kMeanShiftSteps; ++step) {
      support = 0;
      world = {};
      std::fill(sum.begin(), sum.end(), Vec2d{});
      for (const std::size_t m : members[s]) {
        bool near = true;
        for (std::size_t c = 0; c < cameras && near; ++c) {
          const Vec2d& d = matches.disparity_of(m, c);
          const double dx = d.x - estimate[c].x, dy = d.y - estimate[c].y;
          near = dx * dx + dy * dy <= window2;
        }
        if (!near) continue;
        const double w = matches.weight[m];
        support += w;
        world = world + matches.world[m] * w;
        for (std::size_t c = 0; c < cameras; ++c) {
          sum[c].x += w * matches.disparity_of(m, c).x;
          sum[c].y += w * matches.disparity_of(m, c).y;
        }
      }
      if (support <= 0) break;
      for (std::size_t c = 0; c < cameras; ++c) estimate[c] = {sum[c].x / support, sum[c].y / support};
    }
    for (std::size_t c = 0; c < cameras; ++c) {
      SubvolumeDisparity& out = maps[c][s];
      out.disparity = estimate[c];
      out.support = support;
      out.centroid = support > 0 ? world * (1.0 / support) : grid.centre(static_cast<int>(s));
      out.valid = support >= options.min_matches_per_subvolume;
    }
  }
  return maps;
}

CameraDisparity summarise(const CameraModel& model, const std::vector<SubvolumeDisparity>& maps,
                          const SubvolumeGrid& grid) {
  return {figures(model, maps, grid, -1), figures(model, maps, grid, 0), figures(model, maps, grid, grid.nz - 1)};
}

}  // namespace tomorig::calibration::selfcal
