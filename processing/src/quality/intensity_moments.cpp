#include "tomorig/processing/quality/intensity_moments.h"

#include <array>
#include <vector>

#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

// The world position along one axis where the cumulative mass of `marginal` reaches q * total:
// each voxel's mass spread evenly over its width, so the answer moves smoothly with the data.
double quantile_position(const std::vector<double>& marginal, double total, double q, double origin, double voxel) {
  const double target = q * total;
  double cumulative = 0;
  for (std::size_t i = 0; i < marginal.size(); ++i) {
    if (marginal[i] > 0 && cumulative + marginal[i] >= target) {
      const double within = (target - cumulative) / marginal[i];
      return origin + (static_cast<double>(i) - 0.5 + within) * voxel;
    }
    cumulative += marginal[i];
  }
  return origin + (static_cast<double>(marginal.size()) - 0.5) * voxel;
}

}  // namespace

IntensityMoments intensity_moments(const DenseVolume& volume, double tail) {
  if (!(tail > 0 && tail < 0.5)) throw bad_input("intensity_moments: tail must be in (0, 0.5)");
  const VoxelGrid& g = volume.grid;
  IntensityMoments m;
  m.centroid_mm = m.low_mm = m.median_mm = m.high_mm = g.origin;
  std::array<std::vector<double>, 3> marginal{std::vector<double>(static_cast<std::size_t>(g.nx)),
                                              std::vector<double>(static_cast<std::size_t>(g.ny)),
                                              std::vector<double>(static_cast<std::size_t>(g.nz))};
  for (int k = 0; k < g.nz; ++k)
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const float v = volume.at(i, j, k);
        if (v > m.max) m.max = v;
        if (!(v > 0)) continue;
        marginal[0][static_cast<std::size_t>(i)] += v;
        marginal[1][static_cast<std::size_t>(j)] += v;
        marginal[2][static_cast<std::size_t>(k)] += v;
        m.mass += v;
      }
  if (!(m.mass > 0)) return m;
  const std::array<double, 3> origin{g.origin.x, g.origin.y, g.origin.z};
  std::array<double, 3> centroid{}, low{}, median{}, high{};
  for (std::size_t a = 0; a < 3; ++a) {
    double moment = 0;
    for (std::size_t i = 0; i < marginal[a].size(); ++i) moment += marginal[a][i] * static_cast<double>(i);
    centroid[a] = origin[a] + moment / m.mass * g.voxel_size;
    low[a] = quantile_position(marginal[a], m.mass, tail, origin[a], g.voxel_size);
    median[a] = quantile_position(marginal[a], m.mass, 0.5, origin[a], g.voxel_size);
    high[a] = quantile_position(marginal[a], m.mass, 1.0 - tail, origin[a], g.voxel_size);
  }
  m.centroid_mm = {centroid[0], centroid[1], centroid[2]};
  m.low_mm = {low[0], low[1], low[2]};
  m.median_mm = {median[0], median[1], median[2]};
  m.high_mm = {high[0], high[1], high[2]};
  return m;
}

}  // namespace tomorig::quality
