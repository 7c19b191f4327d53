#include "tomorig/processing/quality/depth_profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/core.h>

#include "particles/volume_checks.h"
#include "tomorig/core/error.h"

namespace tomorig::quality {
namespace {

// Adds each entry's value to its slice, skipping the lateral border.
template <class Sink>
void per_slice(const SparseVolume& v, int margin_x, int margin_y, Sink&& sink) {
  const std::uint32_t nx = static_cast<std::uint32_t>(v.grid.nx), ny = static_cast<std::uint32_t>(v.grid.ny);
  for (std::size_t n = 0; n < v.size(); ++n) {
    const std::uint32_t index = v.index[n];
    const std::uint32_t row = index / nx;
    const int i = static_cast<int>(index - row * nx), j = static_cast<int>(row % ny), k = static_cast<int>(row / ny);
    if (i < margin_x || i >= v.grid.nx - margin_x || j < margin_y || j >= v.grid.ny - margin_y) continue;
    sink(index, k, static_cast<double>(v.intensity[n]));
  }
}

}  // namespace

DepthProfile depth_profile(const SparseVolume& volume, const EllipsoidMask& mask, const SparseVolume* truth,
                           int lateral_margin_voxel) {
  particles::detail::check_grid(volume.grid, "depth profile");
  if (truth) particles::detail::check_same_grid(volume.grid, truth->grid, "the reconstruction", "the truth volume");
  if (lateral_margin_voxel < 0)
    throw bad_input(fmt::format("depth profile: lateral_margin_voxel = {}; it must be >= 0", lateral_margin_voxel));
  const VoxelGrid& g = volume.grid;
  const int mx = std::min(lateral_margin_voxel, (g.nx - 1) / 2), my = std::min(lateral_margin_voxel, (g.ny - 1) / 2);
  const double inv_area = 1.0 / (static_cast<double>(g.nx - 2 * mx) * static_cast<double>(g.ny - 2 * my));
  DepthProfile p;
  p.lateral_margin_voxel = lateral_margin_voxel;
  p.total.assign(g.nz, 0.0);
  p.true_part.assign(g.nz, 0.0);
  p.ghost_part.assign(g.nz, 0.0);
  per_slice(volume, mx, my, [&](std::uint32_t index, int k, double v) {
    p.total[k] += v;
    (mask.contains(index) ? p.true_part[k] : p.ghost_part[k]) += v;
  });
  if (truth) {
    p.truth.assign(g.nz, 0.0);
    per_slice(*truth, mx, my, [&](std::uint32_t, int k, double v) { p.truth[k] += v; });
  }
  for (std::vector<double>* profile : {&p.total, &p.true_part, &p.ghost_part, &p.truth})
    for (double& v : *profile) v *= inv_area;
  return p;
}

SignalToNoise reconstruction_snr(const std::vector<double>& profile, double slab_min_voxel, double slab_max_voxel,
                                 double noise_margin_voxel) {
  if (!std::isfinite(slab_min_voxel) || !std::isfinite(slab_max_voxel) || slab_max_voxel < slab_min_voxel)
    throw bad_input(fmt::format("reconstruction SNR: slab [{}, {}] voxel; it needs finite bounds with min <= max",
                                slab_min_voxel, slab_max_voxel));
  if (!(noise_margin_voxel >= 0.0))
    throw bad_input(fmt::format("reconstruction SNR: noise_margin_voxel = {}; it must be >= 0", noise_margin_voxel));
  SignalToNoise s;
  double signal = 0.0, noise = 0.0;
  for (std::size_t k = 0; k < profile.size(); ++k) {
    const double z = static_cast<double>(k);
    if (z >= slab_min_voxel && z <= slab_max_voxel) {
      signal += profile[k];
      ++s.signal_slices;
    } else if (z < slab_min_voxel - noise_margin_voxel || z > slab_max_voxel + noise_margin_voxel) {
      noise += profile[k];
      ++s.noise_slices;
    }
  }
  s.signal = s.signal_slices > 0 ? signal / s.signal_slices : 0.0;
  s.noise = s.noise_slices > 0 ? noise / s.noise_slices : 0.0;
  if (s.signal_slices == 0 || s.noise_slices == 0)
    s.ratio = std::numeric_limits<double>::quiet_NaN();
  else if (s.noise <= 0.0)
    s.ratio = std::numeric_limits<double>::infinity();
  else
    s.ratio = s.signal / s.noise;
  return s;
}

}  // namespace tomorig::quality
