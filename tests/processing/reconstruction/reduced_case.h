#pragma once
// A reduced tpiv-thesis case for reconstruction tests: the thesis's camera geometry (yaw
// -42/-14/14/42 deg, magnification 0.38, 1 px ~ 1 voxel) with small sensors, a small grid of
// 19.5 um voxels centred on the origin, and particles seeded inside that grid, rendered by the
// simulator (noise-free, sigma 0.75 px). The truth volume and Q (Eq. 3.14) are computed here
// from the true positions only.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "tomorig/processing/reconstruction/reconstructor.h"
#include "tomorig/simulators/scene.h"
#include "tomorig/simulators/simulated_rig.h"

namespace recon_test {

struct ReducedCase {
  tomorig::VoxelGrid grid;
  std::vector<tomorig::Vec3d> particles;  // world mm
  std::unique_ptr<tomorig::sim::SimulatedRig> rig;
  std::vector<tomorig::Image> images;

  tomorig::recon::ReconstructionInput input() const {
    tomorig::recon::ReconstructionInput in;
    in.grid = grid;
    in.images = images;
    for (const auto& cam : rig->cameras()) in.cameras.push_back(&cam.model);
    return in;
  }
};

// nxy x nxy x nz voxels; cameras of `pixels` x `pixels`; ppp particle images per pixel.
inline ReducedCase make_case(int nxy, int nz, int pixels, double ppp, std::uint64_t seed = 3) {
  ReducedCase rc;
  rc.grid = tomorig::VoxelGrid::centred(nxy, nxy, nz, 0.0195);
  tomorig::sim::SimulationOptions opt;
  opt.ppp = ppp;
  opt.seed = seed;
  opt.cameras = tomorig::sim::find_case("tpiv-thesis").cameras;
  for (auto& c : opt.cameras) c.width = c.height = pixels;
  rc.rig = std::make_unique<tomorig::sim::SimulatedRig>(opt);
  // Particles at least 2 voxels inside the grid, so that their blobs are whole.
  const double margin = 2.0 * rc.grid.voxel_size;
  const tomorig::Vec3d lo = rc.grid.centre_of(0, 0, 0), hi = rc.grid.centre_of(nxy - 1, nxy - 1, nz - 1);
  const tomorig::sim::Slab slab{{lo.x + margin, lo.y + margin, lo.z + margin},
                                {hi.x - margin, hi.y - margin, hi.z - margin}};
  const auto count = static_cast<std::size_t>(std::llround(ppp * pixels * pixels));
  rc.particles = tomorig::sim::uniform_particles(slab, count, seed);
  for (std::size_t c = 0; c < rc.rig->cameras().size(); ++c) rc.images.push_back(rc.rig->render_signal(c, rc.particles));
  return rc;
}

// Truth: a 3-D Gaussian of diameter 3 voxel (sigma 0.75 voxel) at each true position.
inline tomorig::DenseVolume truth_volume(const tomorig::VoxelGrid& grid, const std::vector<tomorig::Vec3d>& particles) {
  tomorig::DenseVolume truth(grid);
  const double s2 = 2.0 * 0.75 * 0.75;
  for (const auto& p : particles) {
    const tomorig::Vec3d q = grid.voxel_of(p);
    const int ci = static_cast<int>(std::lround(q.x)), cj = static_cast<int>(std::lround(q.y)),
              ck = static_cast<int>(std::lround(q.z));
    for (int k = std::max(0, ck - 3); k <= std::min(grid.nz - 1, ck + 3); ++k)
      for (int j = std::max(0, cj - 3); j <= std::min(grid.ny - 1, cj + 3); ++j)
        for (int i = std::max(0, ci - 3); i <= std::min(grid.nx - 1, ci + 3); ++i) {
          const double d2 = (i - q.x) * (i - q.x) + (j - q.y) * (j - q.y) + (k - q.z) * (k - q.z);
          truth.at(i, j, k) += static_cast<float>(std::exp(-d2 / s2));
        }
  }
  return truth;
}

// Q of Eq. 3.14: normalised correlation of reconstruction and truth.
inline double quality(const tomorig::SparseVolume& v, const tomorig::DenseVolume& truth) {
  double eg = 0, ee = 0, gg = 0;
  for (std::size_t n = 0; n < v.size(); ++n) {
    eg += static_cast<double>(v.intensity[n]) * truth.values[v.index[n]];
    ee += static_cast<double>(v.intensity[n]) * v.intensity[n];
  }
  for (float g : truth.values) gg += static_cast<double>(g) * g;
  return ee > 0 && gg > 0 ? eg / std::sqrt(ee * gg) : 0.0;
}

}  // namespace recon_test
