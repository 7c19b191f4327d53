// Quality metrics against volumes of known content: the truth volume itself, plus ghost
// blobs at known places, minus particles, shifted by known amounts. Every expected value is
// written out here from the definitions (thesis Sect. 3.2.2), not taken from the code.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/particles/sparsify.h"
#include "tomorig/processing/quality/position_matching.h"
#include "tomorig/processing/quality/quality_factor.h"
#include "tomorig/processing/quality/quality_report.h"
#include "tomorig/simulators/truth_volume.h"

namespace {

using tomorig::DenseVolume;
using tomorig::SparseVolume;
using tomorig::Vec3d;
using tomorig::VoxelGrid;
using namespace tomorig::quality;

VoxelGrid grid(int nx, int ny, int nz) { return VoxelGrid::centred(nx, ny, nz, 0.0195); }

std::vector<Vec3d> to_world(const VoxelGrid& g, const std::vector<Vec3d>& voxels) {
  std::vector<Vec3d> w;
  for (const Vec3d& v : voxels) w.push_back(g.centre_of(v.x, v.y, v.z));
  return w;
}

SparseVolume blobs(const VoxelGrid& g, const std::vector<Vec3d>& voxels, double peak = 1.0) {
  tomorig::sim::TruthVolumeOptions opt;
  opt.peak = peak;
  return tomorig::sim::truth_volume(g, to_world(g, voxels), opt);
}

SparseVolume add(const SparseVolume& a, const SparseVolume& b) {
  DenseVolume d = a.to_dense();
  for (std::size_t n = 0; n < b.size(); ++n) d.values[b.index[n]] += b.intensity[n];
  return tomorig::particles::sparsify(d);
}

// Positions on voxel centres, at least `spacing` apart and `margin` from the faces, so every
// blob has the same shape.
std::vector<Vec3d> lattice_positions(const VoxelGrid& g, int count, double spacing, int margin, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> ux(margin, g.nx - 1 - margin), uy(margin, g.ny - 1 - margin),
      uz(margin, g.nz - 1 - margin);
  std::vector<Vec3d> out;
  while (static_cast<int>(out.size()) < count) {
    const Vec3d p{double(ux(rng)), double(uy(rng)), double(uz(rng))};
    bool free = true;
    for (const Vec3d& q : out) free = free && (p - q).norm() >= spacing;
    if (free) out.push_back(p);
  }
  return out;
}

double sum_of_squares(const SparseVolume& v) {
  double s = 0;
  for (float x : v.intensity) s += double(x) * x;
  return s;
}

// Eq. 3.14 straight from the definition, over a dense box [x0, x1) x [y0, y1) x [z0, z1).
double reference_q(const DenseVolume& e, const DenseVolume& t, int x0, int x1, int y0, int y1, int z0, int z1) {
  double eg = 0, ee = 0, gg = 0;
  for (int k = z0; k < z1; ++k)
    for (int j = y0; j < y1; ++j)
      for (int i = x0; i < x1; ++i) {
        const double a = e.at(i, j, k), b = t.at(i, j, k);
        eg += a * b, ee += a * a, gg += b * b;
      }
  return ee > 0 && gg > 0 ? eg / std::sqrt(ee * gg) : 0.0;
}

TEST(QualityFactor, TruthAgainstItselfAndScaledIsOne) {
  const VoxelGrid g = grid(64, 48, 40);
  const SparseVolume t = blobs(g, lattice_positions(g, 80, 4.0, 2, 1));
  const QualityFactor q = quality_factor(t, t, {16, 8});
  EXPECT_NEAR(q.global, 1.0, 1e-12);
  EXPECT_NEAR(q.windowed, 1.0, 1e-12);
  SparseVolume scaled = t;
  for (float& v : scaled.intensity) v *= 3.0f;
  EXPECT_NEAR(quality_factor(scaled, t).global, 1.0, 1e-7);
}

TEST(QualityFactor, AnAddedGhostLowersQByTheExpectedAmount) {
  const VoxelGrid g = grid(64, 48, 40);
  const std::vector<Vec3d> particles{{10, 10, 10}, {30, 20, 20}, {50, 30, 12}, {20, 40, 30}};
  const SparseVolume truth = blobs(g, particles);
  const SparseVolume ghost = blobs(g, {{45.3, 10.6, 30.2}}, 0.7);  // far from every particle
  // Disjoint supports: sum(E G) = sum(G^2), sum(E^2) = sum(G^2) + sum(ghost^2).
  const double gg = sum_of_squares(truth), hh = sum_of_squares(ghost);
  const double expected = std::sqrt(gg / (gg + hh));
  const QualityFactor q = quality_factor(add(truth, ghost), truth);
  EXPECT_NEAR(q.global, expected, 1e-6);
  EXPECT_LT(q.global, 0.95);  // the ghost is not negligible: the test can fail
}

TEST(QualityFactor, WindowOriginsCoverGridsThatAreNotAMultipleOfTheWindow) {
  EXPECT_EQ(window_origins(512, {}).size(), 15u);  // thesis: 15 x 15 x 4
  EXPECT_EQ(window_origins(160, {}), (std::vector<int>{0, 32, 64, 96}));
  EXPECT_EQ(window_origins(150, {}), (std::vector<int>{0, 32, 64, 86}));  // one more, flush with the end
  EXPECT_EQ(window_origins(40, {}), (std::vector<int>{0}));              // shorter than a window
  EXPECT_THROW(window_origins(100, {64, 0}), tomorig::Error);
  EXPECT_THROW(window_origins(100, {16, 32}), tomorig::Error);  // step > size leaves gaps
}

TEST(QualityFactor, WindowedQMatchesTheDefinitionOnAnOddGrid) {
  const VoxelGrid g = grid(45, 37, 30);  // windows 16 at step 8: 4 + 1, 3 + 1, 2 + 1 origins
  const std::vector<Vec3d> ps = lattice_positions(g, 60, 3.0, 1, 2);
  const SparseVolume truth = blobs(g, ps);
  // A reconstruction with shifted particles, one ghost and one particle missing.
  std::vector<Vec3d> moved;
  for (std::size_t n = 1; n < ps.size(); ++n) moved.push_back(ps[n] + Vec3d{0.4, -0.3, 0.7});
  moved.push_back({40.2, 3.3, 27.1});
  const SparseVolume recon = blobs(g, moved, 0.8);
  const WindowOptions w{16, 8};
  const QualityFactor q = quality_factor(recon, truth, w);
  const DenseVolume e = recon.to_dense(), t = truth.to_dense();
  const std::vector<int> ox{0, 8, 16, 24, 29}, oy{0, 8, 16, 21}, oz{0, 8, 14};
  ASSERT_EQ(q.windows_x, 5);
  ASSERT_EQ(q.windows_y, 4);
  ASSERT_EQ(q.windows_z, 3);
  double sum = 0;
  std::size_t used = 0;
  for (std::size_t c = 0; c < oz.size(); ++c)
    for (std::size_t b = 0; b < oy.size(); ++b)
      for (std::size_t a = 0; a < ox.size(); ++a) {
        const double expected = reference_q(e, t, ox[a], ox[a] + 16, oy[b], oy[b] + 16, oz[c], oz[c] + 16);
        const double got = q.window_q[a + ox.size() * (b + oy.size() * c)];
        ASSERT_FALSE(std::isnan(got));  // every window holds particles here
        EXPECT_NEAR(got, expected, 1e-9);
        sum += expected;
        ++used;
      }
  EXPECT_EQ(q.windows_used, used);
  EXPECT_NEAR(q.windowed, sum / used, 1e-9);
  EXPECT_NEAR(q.global, reference_q(e, t, 0, 45, 0, 37, 0, 30), 1e-9);
  EXPECT_LT(q.global, 0.9);
}

TEST(QualityFactor, SameResultOnOneAndTwoThreads) {
  const VoxelGrid g = grid(64, 64, 32);
  const std::vector<Vec3d> ps = lattice_positions(g, 200, 2.0, 0, 3);
  std::vector<Vec3d> moved;
  for (const Vec3d& p : ps) moved.push_back(p + Vec3d{0.3, 0.1, -0.2});
  const SparseVolume t = blobs(g, ps), e = blobs(g, moved);
  const QualityFactor a = quality_factor(e, t, {}, 1), b = quality_factor(e, t, {}, 2);
  EXPECT_EQ(a.global, b.global);
  EXPECT_EQ(a.windowed, b.windowed);
}

TEST(QualityFactor, RejectsDifferentGridsAndMalformedVolumes) {
  const SparseVolume a = blobs(grid(16, 16, 16), {{8, 8, 8}});
  const SparseVolume b = blobs(grid(16, 16, 17), {{8, 8, 8}});
  EXPECT_THROW(quality_factor(a, b), tomorig::Error);
  SparseVolume broken = a;
  std::swap(broken.index[0], broken.index[1]);
  EXPECT_THROW(quality_factor(broken, a), tomorig::Error);
}

TEST(PositionMatching, KnownShiftGivesItsRmsAndOutOfReachShiftsAreNotDetections) {
  const VoxelGrid g = grid(64, 64, 32);
  const std::vector<Vec3d> truth = lattice_positions(g, 100, 5.0, 2, 4);
  std::vector<Vec3d> detected;
  for (std::size_t n = 0; n < truth.size(); ++n) {
    const double s = n % 2 ? 1.0 : -1.0;  // alternating sign: RMS = |shift|, mean = 0
    detected.push_back(truth[n] + Vec3d{0.3 * s, -0.2 * s, 0.5 * s});
  }
  const PositionMatch m = match_positions(detected, truth, g);
  EXPECT_EQ(m.matched, truth.size());
  EXPECT_DOUBLE_EQ(m.detected_fraction, 1.0);
  EXPECT_NEAR(m.rms_voxel.x, 0.3, 1e-9);
  EXPECT_NEAR(m.rms_voxel.y, 0.2, 1e-9);
  EXPECT_NEAR(m.rms_voxel.z, 0.5, 1e-9);
  EXPECT_NEAR(m.mean_voxel.z, 0.0, 1e-9);
  // (1.0 / 1.5)^2 + (1.2 / 1.8)^2 = 0.89 <= 1: inside the ellipsoid; 1.45 in z alone too;
  // (1.2 / 1.5)^2 + (1.2 / 1.8)^2 = 1.08: outside, though inside the 1.5 x 1.5 x 1.8 box.
  const std::vector<Vec3d> t1{{20, 20, 10}};
  const std::vector<Vec3d> in{{21.0, 20, 11.2}}, out{{21.2, 20, 11.2}};
  EXPECT_EQ(match_positions(in, t1, g).matched, 1u);
  EXPECT_EQ(match_positions(out, t1, g).matched, 0u);
}

TEST(PositionMatching, OneToOneClosestFirstAndParticlesOutsideTheGridLeftOut) {
  const VoxelGrid g = grid(32, 32, 32);
  const std::vector<Vec3d> truth{{10, 10, 10}, {11, 10, 10}, {-3, 5, 5}};
  const std::vector<Vec3d> detected{{10.1, 10, 10}, {10.4, 10, 10}, {10.5, 10.6, 10}};
  const PositionMatch m = match_positions(detected, truth, g);
  EXPECT_EQ(m.true_particles, 2u);  // (-3, 5, 5) is outside
  EXPECT_EQ(m.matched, 2u);
  EXPECT_EQ(m.truth_of_detection[0], 0u);  // 0.1 from truth 0
  EXPECT_EQ(m.truth_of_detection[1], 1u);  // 0.6 from truth 1 (truth 0 is taken)
  EXPECT_EQ(m.truth_of_detection[2], PositionMatch::npos);
}

struct Scene {
  VoxelGrid g = grid(96, 96, 48);
  std::vector<Vec3d> particles;
  std::vector<Vec3d> ghosts;
  Scene() {
    // Particles in z 12..36 (the seeded slab), ghosts anywhere, all on voxel centres and
    // > 2 * 2.625 * sqrt(3) voxel apart, so the blobs' 3.5-sigma boxes never touch.
    for (const Vec3d& p : lattice_positions(g, 110, 9.2, 3, 5)) {
      if (p.z >= 12 && p.z <= 36 && particles.size() < 50)
        particles.push_back(p);
      else if (ghosts.size() < 15)
        ghosts.push_back(p);
    }
  }
};

TEST(QualityReport, TruthAgainstItselfIsPerfect) {
  const Scene s;
  const std::vector<Vec3d> world = to_world(s.g, s.particles);
  const QualityEvaluator judge(s.g, world);
  const QualityReport r = judge.evaluate(judge.truth_volume());
  EXPECT_NEAR(r.q_global, 1.0, 1e-12);
  EXPECT_NEAR(r.q_windowed, 1.0, 1e-12);
  EXPECT_EQ(r.true_blobs, s.particles.size());
  EXPECT_EQ(r.ghost_blobs, 0u);
  EXPECT_EQ(r.ghost_true_count_ratio, 0.0);
  EXPECT_TRUE(std::isinf(r.true_ghost_intensity_ratio));
  EXPECT_EQ(r.matched_particles, s.particles.size());
  EXPECT_DOUBLE_EQ(r.detected_fraction, 1.0);
  for (double rms : r.position_rms_voxel) EXPECT_LT(rms, 1e-3);
}

TEST(QualityReport, GhostCountsIntensitiesAndDetectedFractionAreExact) {
  const Scene s;
  ASSERT_GE(s.ghosts.size(), 10u);
  ASSERT_EQ(s.particles.size(), 50u);
  // Reconstruction: 40 of the 50 particles at peak 1, every ghost at peak 0.25.
  const std::vector<Vec3d> kept(s.particles.begin(), s.particles.begin() + 40);
  const SparseVolume recon = add(blobs(s.g, kept, 1.0), blobs(s.g, s.ghosts, 0.25));
  const QualityReport r = evaluate_quality(recon, to_world(s.g, s.particles));
  EXPECT_EQ(r.true_blobs, 40u);
  EXPECT_EQ(r.ghost_blobs, s.ghosts.size());
  EXPECT_DOUBLE_EQ(r.ghost_true_count_ratio, s.ghosts.size() / 40.0);
  // Same shape (voxel-centred, isolated): mean intensity per voxel scales with the peak.
  EXPECT_NEAR(r.true_ghost_intensity_ratio, 4.0, 1e-5);
  EXPECT_EQ(r.true_particles, 50u);
  EXPECT_EQ(r.matched_particles, 40u);
  EXPECT_DOUBLE_EQ(r.detected_fraction, 0.8);
  // Q from the definition: supports are disjoint, so sum(E G) = sum(G_kept^2).
  const SparseVolume truth = blobs(s.g, s.particles), kept_truth = blobs(s.g, kept),
                     ghost = blobs(s.g, s.ghosts, 0.25);
  const double expected_q = sum_of_squares(kept_truth) /
                            std::sqrt((sum_of_squares(kept_truth) + sum_of_squares(ghost)) * sum_of_squares(truth));
  EXPECT_NEAR(r.q_global, expected_q, 1e-6);
  // Dense input gives the same report.
  const QualityReport d = evaluate_quality(recon.to_dense(), to_world(s.g, s.particles));
  EXPECT_EQ(d.q_global, r.q_global);
  EXPECT_EQ(d.ghost_blobs, r.ghost_blobs);
  EXPECT_EQ(d.matched_particles, r.matched_particles);
}

TEST(QualityReport, DepthProfileSplitsTrueAndGhostIntensityPerSlice) {
  const Scene s;
  const SparseVolume truth = blobs(s.g, s.particles);
  const SparseVolume ghost = blobs(s.g, s.ghosts, 0.25);
  const QualityReport r = evaluate_quality(add(truth, ghost), to_world(s.g, s.particles));
  const DepthProfile& p = r.depth_profile;
  ASSERT_EQ(p.total.size(), 48u);
  // Per slice, from the dense volumes: the ghosts sit > 9 voxel from any particle, so the
  // mask (3 x 3 x 4.5 voxel) holds truth voxels only and the ghost part is the truth's
  // tails outside the mask plus the ghost blobs.
  const DenseVolume t = truth.to_dense(), h = ghost.to_dense();
  const tomorig::quality::EllipsoidMask mask(s.g, s.particles, {3.0, 3.0, 4.5});
  const double area = 96.0 * 96.0;
  for (int k = 0; k < 48; ++k) {
    double total = 0, inside = 0, truth_sum = 0;
    for (int j = 0; j < 96; ++j)
      for (int i = 0; i < 96; ++i) {
        const double v = double(t.at(i, j, k)) + h.at(i, j, k);
        total += v;
        truth_sum += t.at(i, j, k);
        if (mask.contains(static_cast<std::uint32_t>(s.g.linear(i, j, k)))) inside += v;
      }
    EXPECT_NEAR(p.total[k], total / area, 1e-6);
    EXPECT_NEAR(p.true_part[k], inside / area, 1e-6);
    EXPECT_NEAR(p.ghost_part[k], (total - inside) / area, 1e-6);
    EXPECT_NEAR(p.truth[k], truth_sum / area, 1e-6);
  }
  EXPECT_GT(r.ghost_intensity_fraction, 0.0);
}

TEST(QualityReport, ReconstructionSnrIsSlabLevelOverOutsideLevel) {
  // Profile: 5 inside the slab [10, 20], 100 in the margin next to it (excluded), 1 beyond.
  std::vector<double> profile(30, 1.0);
  for (int k = 10; k <= 20; ++k) profile[k] = 5.0;
  profile[8] = profile[9] = profile[21] = profile[22] = 100.0;
  const SignalToNoise s = reconstruction_snr(profile, 10.0, 20.0, 2.25);
  EXPECT_DOUBLE_EQ(s.ratio, 5.0);
  EXPECT_EQ(s.signal_slices, 11u);
  EXPECT_EQ(s.noise_slices, 30u - 11u - 4u);
  EXPECT_TRUE(std::isnan(reconstruction_snr(profile, 0.0, 29.0).ratio));  // nothing outside
  std::vector<double> clean(30, 0.0);
  clean[15] = 1.0;
  EXPECT_TRUE(std::isinf(reconstruction_snr(clean, 10.0, 20.0).ratio));

  // End to end: truth plus a uniform background b in every voxel. The slab is the true
  // particles' z range; slices more than 2.25 voxel beyond it hold b and the truth's last
  // tails; expected from the dense sums.
  const Scene sc;
  DenseVolume d = blobs(sc.g, sc.particles).to_dense();
  const DenseVolume truth = d;
  const float b = 0.002f;
  for (float& v : d.values) v += b;
  const QualityReport r = evaluate_quality(d, to_world(sc.g, sc.particles));
  double zmin = 1e9, zmax = -1e9;
  for (const Vec3d& p : sc.particles) zmin = std::min(zmin, p.z), zmax = std::max(zmax, p.z);
  double signal = 0, noise = 0;
  int ns = 0, nn = 0;
  for (int k = 0; k < 48; ++k) {
    double slice = 0;
    for (int j = 0; j < 96; ++j)
      for (int i = 0; i < 96; ++i) slice += double(truth.at(i, j, k)) + b;
    slice /= 96.0 * 96.0;
    if (k >= zmin && k <= zmax) signal += slice, ++ns;
    else if (k < zmin - 2.25 || k > zmax + 2.25) noise += slice, ++nn;
  }
  ASSERT_GT(nn, 0);
  EXPECT_NEAR(r.snr.ratio, (signal / ns) / (noise / nn), 1e-4 * r.snr.ratio);
  EXPECT_GT(r.snr.ratio, 1.0);  // the slab outshines the background-only slices
}

TEST(QualityReport, RejectsBadInput) {
  const Scene s;
  const std::vector<Vec3d> world = to_world(s.g, s.particles);
  const QualityEvaluator judge(s.g, world);
  EXPECT_THROW(judge.evaluate(blobs(grid(96, 96, 47), s.particles)), tomorig::Error);  // other grid
  std::vector<Vec3d> with_nan = world;
  with_nan[3].y = NAN;
  EXPECT_THROW(QualityEvaluator(s.g, with_nan), tomorig::Error);
  QualityOptions bad;
  bad.detection_radius_voxel = {1.5, 0.0, 1.8};
  EXPECT_THROW(QualityEvaluator(s.g, world, bad), tomorig::Error);
  bad = {};
  bad.slab_z_min_mm = 0.0;  // max missing
  try {
    QualityEvaluator(s.g, world, bad);
    FAIL() << "half a slab accepted";
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("slab_z_max_mm"), std::string::npos) << e.what();
  }
}

}  // namespace
