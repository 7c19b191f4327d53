#include "tomorig/processing/quality/position_matching.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

bool inside_grid(const Vec3d& v, const VoxelGrid& g) {
  return v.x >= -0.5 && v.x < g.nx - 0.5 && v.y >= -0.5 && v.y < g.ny - 0.5 && v.z >= -0.5 && v.z < g.nz - 0.5;
}

// Cells at least as large as the acceptance ellipsoid, so a detection's candidates lie in
// its own cell and the 26 around it.
struct CellGrid {
  double size = 1.0;
  std::int64_t nx = 1, ny = 1, nz = 1;
  CellGrid(const VoxelGrid& g, double cell) : size(cell) {
    nx = static_cast<std::int64_t>(std::ceil((g.nx + 1) / cell)) + 1;
    ny = static_cast<std::int64_t>(std::ceil((g.ny + 1) / cell)) + 1;
    nz = static_cast<std::int64_t>(std::ceil((g.nz + 1) / cell)) + 1;
  }
  std::int64_t coord(double v, std::int64_t n) const {
    return std::clamp(static_cast<std::int64_t>(std::floor((v + 0.5) / size)), std::int64_t{0}, n - 1);
  }
  std::int64_t key(std::int64_t cx, std::int64_t cy, std::int64_t cz) const { return cx + nx * (cy + ny * cz); }
};

struct Candidate {
  double distance2;  // normalised: <= 1 inside the ellipsoid
  std::size_t detection, truth;
};

}  // namespace

void MatchOptions::validate() const {
  const Vec3d& r = radius_voxel;
  if (!(r.x > 0 && r.y > 0 && r.z > 0) || !std::isfinite(r.x) || !std::isfinite(r.y) || !std::isfinite(r.z))
    throw bad_input(fmt::format("position matching: radius_voxel = {} x {} x {}; each must be a finite value > 0",
                                r.x, r.y, r.z));
}

PositionMatch match_positions(std::span<const Vec3d> detected_voxel, std::span<const Vec3d> truth_voxel,
                              const VoxelGrid& grid, const MatchOptions& options) {
  options.validate();
  particles::detail::check_grid(grid, "position matching");
  const Vec3d& r = options.radius_voxel;
  const CellGrid cells(grid, std::max({r.x, r.y, r.z}));

  // True particles in the grid, sorted by cell so each cell's members are one range.
  std::vector<std::pair<std::int64_t, std::size_t>> by_cell;
  by_cell.reserve(truth_voxel.size());
  for (std::size_t t = 0; t < truth_voxel.size(); ++t) {
    const Vec3d& v = truth_voxel[t];
    if (!inside_grid(v, grid)) continue;
    by_cell.emplace_back(cells.key(cells.coord(v.x, cells.nx), cells.coord(v.y, cells.ny), cells.coord(v.z, cells.nz)), t);
  }
  std::sort(by_cell.begin(), by_cell.end());

  std::vector<Candidate> candidates;
  for (std::size_t d = 0; d < detected_voxel.size(); ++d) {
    const Vec3d& p = detected_voxel[d];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    const std::int64_t cx = cells.coord(p.x, cells.nx), cy = cells.coord(p.y, cells.ny), cz = cells.coord(p.z, cells.nz);
    for (std::int64_t z = std::max<std::int64_t>(cz - 1, 0); z <= std::min(cz + 1, cells.nz - 1); ++z)
      for (std::int64_t y = std::max<std::int64_t>(cy - 1, 0); y <= std::min(cy + 1, cells.ny - 1); ++y) {
        const std::int64_t x0 = std::max<std::int64_t>(cx - 1, 0), x1 = std::min(cx + 1, cells.nx - 1);
        auto it = std::lower_bound(by_cell.begin(), by_cell.end(), std::make_pair(cells.key(x0, y, z), std::size_t{0}));
        const std::int64_t end_key = cells.key(x1, y, z);
        for (; it != by_cell.end() && it->first <= end_key; ++it) {
          const Vec3d& t = truth_voxel[it->second];
          const double dx = (p.x - t.x) / r.x, dy = (p.y - t.y) / r.y, dz = (p.z - t.z) / r.z;
          const double d2 = dx * dx + dy * dy + dz * dz;
          if (d2 <= 1.0) candidates.push_back({d2, d, it->second});
        }
      }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.distance2, a.detection, a.truth) < std::tie(b.distance2, b.detection, b.truth);
  });

  PositionMatch m;
  m.true_particles = by_cell.size();
  m.detections = detected_voxel.size();
  m.truth_of_detection.assign(detected_voxel.size(), PositionMatch::npos);
  std::vector<bool> truth_taken(truth_voxel.size(), false);
  Vec3d sum, sum2;
  for (const Candidate& c : candidates) {
    if (truth_taken[c.truth] || m.truth_of_detection[c.detection] != PositionMatch::npos) continue;
    truth_taken[c.truth] = true;
    m.truth_of_detection[c.detection] = c.truth;
    ++m.matched;
    const Vec3d e = detected_voxel[c.detection] - truth_voxel[c.truth];
    sum = sum + e;
    sum2 = sum2 + Vec3d{e.x * e.x, e.y * e.y, e.z * e.z};
  }
  if (m.matched > 0) {
    const double inv = 1.0 / static_cast<double>(m.matched);
    m.mean_voxel = sum * inv;
    m.rms_voxel = {std::sqrt(sum2.x * inv), std::sqrt(sum2.y * inv), std::sqrt(sum2.z * inv)};
  }
  m.detected_fraction = m.true_particles > 0 ? static_cast<double>(m.matched) / m.true_particles : 0.0;
  return m;
}

}  // namespace tomorig::quality
