// Ground-truth volume: flux, centroid, peak, overlap and determinism, against closed forms of
// the sampled 3-D Gaussian written out here.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/truth_volume.h"

namespace {

using tomorig::DenseVolume;
using tomorig::SparseVolume;
using tomorig::Vec3d;
using tomorig::VoxelGrid;
using tomorig::sim::TruthVolumeOptions;

constexpr double kPi = 3.14159265358979323846;

// A 40^3 grid of 0.02 mm voxels with voxel (0, 0, 0) at world (1, 2, 3) mm: not centred, so
// world/voxel mix-ups show.
VoxelGrid test_grid() { return {40, 40, 40, {1.0, 2.0, 3.0}, 0.02}; }

struct Moments {
  double sum = 0;
  Vec3d centroid;
};

Moments moments(const SparseVolume& v) {
  Moments m;
  for (std::size_t n = 0; n < v.size(); ++n) {
    const std::uint32_t idx = v.index[n];
    const int i = idx % v.grid.nx, j = (idx / v.grid.nx) % v.grid.ny, k = idx / (v.grid.nx * v.grid.ny);
    m.sum += v.intensity[n];
    m.centroid = m.centroid + Vec3d{double(i), double(j), double(k)} * v.intensity[n];
  }
  m.centroid = m.centroid * (1.0 / m.sum);
  return m;
}

TEST(TruthVolume, BlobIntegratesToPeakTimesGaussianVolumeAndCentresOnTheParticle) {
  const VoxelGrid g = test_grid();
  const double sigma = 0.75;
  const double flux = std::pow(2 * kPi, 1.5) * sigma * sigma * sigma;  // peak 1
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(15.0, 25.0);
  for (int trial = 0; trial < 8; ++trial) {
    const Vec3d voxel{u(rng), u(rng), u(rng)};
    const Vec3d world = g.centre_of(voxel.x, voxel.y, voxel.z);
    // Default 3.5-sigma box: < 1 % of the flux lost, centroid within 0.005 voxel.
    const Moments m = moments(tomorig::sim::truth_volume(g, {&world, 1}));
    EXPECT_NEAR(m.sum / flux, 1.0, 0.01);
    EXPECT_NEAR(m.centroid.x, voxel.x, 0.005);
    EXPECT_NEAR(m.centroid.y, voxel.y, 0.005);
    EXPECT_NEAR(m.centroid.z, voxel.z, 0.005);
    // 5-sigma box: the sampled Gaussian reproduces the continuous integral and centre (to the
    // ~1e-4 voxel ripple that sampling at sigma = 0.75 voxel leaves on the first moment).
    TruthVolumeOptions wide;
    wide.cutoff_sigmas = 5.0;
    const Moments w = moments(tomorig::sim::truth_volume(g, {&world, 1}, wide));
    EXPECT_NEAR(w.sum / flux, 1.0, 1e-4);
    EXPECT_NEAR(w.centroid.x, voxel.x, 2e-4);
    EXPECT_NEAR(w.centroid.y, voxel.y, 2e-4);
    EXPECT_NEAR(w.centroid.z, voxel.z, 2e-4);
  }
}

TEST(TruthVolume, VoxelValuesAreTheGaussianAtVoxelCentresAndOverlapsAdd) {
  const VoxelGrid g = test_grid();
  TruthVolumeOptions opt;
  opt.peak = 2.0;
  const Vec3d a{20.0, 20.0, 20.0}, b{21.3, 19.6, 20.4};
  const std::vector<Vec3d> world{g.centre_of(a.x, a.y, a.z), g.centre_of(b.x, b.y, b.z)};
  const DenseVolume d = tomorig::sim::truth_volume_dense(g, world, opt);
  const auto gauss = [](const Vec3d& c, int i, int j, int k) {
    const double r2 = (i - c.x) * (i - c.x) + (j - c.y) * (j - c.y) + (k - c.z) * (k - c.z);
    return 2.0 * std::exp(-r2 / (2 * 0.75 * 0.75));
  };
  EXPECT_NEAR(d.at(20, 20, 20), gauss(a, 20, 20, 20) + gauss(b, 20, 20, 20), 1e-5);
  EXPECT_NEAR(d.at(21, 20, 20), gauss(a, 21, 20, 20) + gauss(b, 21, 20, 20), 1e-5);
  EXPECT_NEAR(d.at(22, 19, 21), gauss(a, 22, 19, 21) + gauss(b, 22, 19, 21), 1e-5);
  // Outside a's box (|k - 20| = 3 > 2.625) only b contributes.
  EXPECT_NEAR(d.at(21, 20, 23), gauss(b, 21, 20, 23), 1e-6);
  EXPECT_EQ(d.at(10, 10, 10), 0.0f);
}

TEST(TruthVolume, SparseIsSortedUniqueAndEqualsDense) {
  const VoxelGrid g = test_grid();
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 43.0);  // some outside the grid, some clipped
  std::vector<Vec3d> world;
  for (int n = 0; n < 300; ++n) world.push_back(g.centre_of(u(rng), u(rng), u(rng)));
  const SparseVolume s = tomorig::sim::truth_volume(g, world);
  for (std::size_t n = 1; n < s.size(); ++n) ASSERT_LT(s.index[n - 1], s.index[n]);
  const DenseVolume d = tomorig::sim::truth_volume_dense(g, world);
  const DenseVolume from_sparse = s.to_dense();
  EXPECT_EQ(d.values, from_sparse.values);
  // Every stored voxel is non-zero and no non-stored voxel is.
  std::size_t non_zero = 0;
  for (float v : d.values) non_zero += v > 0.0f ? 1 : 0;
  EXPECT_EQ(non_zero, s.size());
}

TEST(TruthVolume, ResultDoesNotDependOnThreadCount) {
  const VoxelGrid g = test_grid();
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 39.0);
  std::vector<Vec3d> world;
  for (int n = 0; n < 2000; ++n) world.push_back(g.centre_of(u(rng), u(rng), u(rng)));  // dense: many overlaps
  TruthVolumeOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const SparseVolume a = tomorig::sim::truth_volume(g, world, one), b = tomorig::sim::truth_volume(g, world, two);
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.intensity, b.intensity);
}

TEST(TruthVolume, ParticleOnTheGridFaceKeepsTheInsideHalf) {
  const VoxelGrid g = test_grid();
  TruthVolumeOptions wide;
  wide.cutoff_sigmas = 5.0;
  const Vec3d world = g.centre_of(0.0, 20.0, 20.0);  // centred on the first voxel layer
  const Moments m = moments(tomorig::sim::truth_volume(g, {&world, 1}, wide));
  // Layers i = 0, 1, 2, ...: the sampled Gaussian's share at i >= 0 is (1 + w0) / 2 of it,
  // w0 the centre layer's share of the 1-D sum.
  double total = 0, centre = 1.0;
  for (int i = -5; i <= 5; ++i) total += std::exp(-i * i / (2 * 0.75 * 0.75));
  const double inside = 0.5 * (1 + centre / total);
  EXPECT_NEAR(m.sum / (std::pow(2 * kPi, 1.5) * 0.421875 * inside), 1.0, 1e-4);
}

TEST(TruthVolume, RejectsBadInputWithMessages) {
  const VoxelGrid g = test_grid();
  const Vec3d nan_point{NAN, 0, 0};
  EXPECT_THROW(tomorig::sim::truth_volume(g, {&nan_point, 1}), tomorig::Error);
  const Vec3d ok = g.centre_of(5, 5, 5);
  VoxelGrid empty = g;
  empty.nz = 0;
  EXPECT_THROW(tomorig::sim::truth_volume(empty, {&ok, 1}), tomorig::Error);
  TruthVolumeOptions bad;
  bad.sigma_voxel = 0.0;
  try {
    tomorig::sim::truth_volume(g, {&ok, 1}, bad);
    FAIL() << "sigma 0 accepted";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("sigma_voxel"), std::string::npos) << e.what();
  }
  bad = {};
  bad.cutoff_sigmas = 100.0;
  EXPECT_THROW(tomorig::sim::truth_volume(g, {&ok, 1}, bad), tomorig::Error);
  EXPECT_EQ(tomorig::sim::truth_volume(g, {}).size(), 0u);
}

}  // namespace
