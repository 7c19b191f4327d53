// MLOS, FMART, SMART and MART on reduced tpiv-thesis cases, judged against the simulator's
// true particle positions only: Q (Eq. 3.14) against Gaussian truth blobs, and the centroid of
// the reconstructed intensity around every true particle.
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "reduced_case.h"

namespace {

using namespace tomorig;
using recon::ReconstructionOptions;
using recon::ReconstructionReport;

// 128 x 128 x 40 voxels seen by 140 x 140 px cameras, 0.05 ppp (980 particles).
const recon_test::ReducedCase& small_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(128, 40, 140, 0.05);
  return rc;
}
const DenseVolume& small_truth() {
  static const DenseVolume truth = recon_test::truth_volume(small_case().grid, small_case().particles);
  return truth;
}

SparseVolume run(const std::string& algorithm, const recon_test::ReducedCase& rc, ReconstructionReport& report,
                 int iterations = 6, int threads = 0) {
  ReconstructionOptions o;
  o.algorithm = algorithm;
  o.max_iterations = iterations;
  o.threads = threads;
  if (algorithm == "smart") o.relaxation = 1.5;
  return recon::make_reconstructor(o)->reconstruct(rc.input(), report);
}

// Median over true particles of |centroid - truth| per axis, the centroid being the
// intensity-weighted mean over the 5 x 5 x 5 voxels around the particle's nearest voxel.
Vec3d median_centroid_error(const SparseVolume& v, const std::vector<Vec3d>& particles) {
  const DenseVolume dense = v.to_dense();
  const VoxelGrid& g = v.grid;
  std::vector<double> ex, ey, ez;
  for (const Vec3d& p : particles) {
    const Vec3d q = g.voxel_of(p);
    const int ci = static_cast<int>(std::lround(q.x)), cj = static_cast<int>(std::lround(q.y)),
              ck = static_cast<int>(std::lround(q.z));
    double s = 0, sx = 0, sy = 0, sz = 0;
    for (int k = std::max(0, ck - 2); k <= std::min(g.nz - 1, ck + 2); ++k)
      for (int j = std::max(0, cj - 2); j <= std::min(g.ny - 1, cj + 2); ++j)
        for (int i = std::max(0, ci - 2); i <= std::min(g.nx - 1, ci + 2); ++i) {
          const double w = dense.at(i, j, k);
          s += w;
          sx += w * i;
          sy += w * j;
          sz += w * k;
        }
    if (s <= 0) {  // nothing reconstructed there: count as a full voxel off
      ex.push_back(1);
      ey.push_back(1);
      ez.push_back(1);
      continue;
    }
    ex.push_back(std::fabs(sx / s - q.x));
    ey.push_back(std::fabs(sy / s - q.y));
    ez.push_back(std::fabs(sz / s - q.z));
  }
  auto median = [](std::vector<double>& e) {
    std::nth_element(e.begin(), e.begin() + e.size() / 2, e.end());
    return e[e.size() / 2];
  };
  return {median(ex), median(ey), median(ez)};
}

TEST(Reconstruction, MlosSupportHoldsEveryTrueParticle) {
  ReconstructionReport report;
  const SparseVolume v = run("mlos", small_case(), report);
  const DenseVolume dense = v.to_dense();
  std::size_t found = 0;
  for (const Vec3d& p : small_case().particles) {
    const Vec3d q = v.grid.voxel_of(p);
    found += dense.at(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)),
                      static_cast<int>(std::lround(q.z))) > 0;
  }
  EXPECT_GE(found, small_case().particles.size() * 99 / 100);
  // Sparse: a small fraction of the grid is active.
  EXPECT_LT(report.active_voxels, v.grid.voxel_count() / 3);
  EXPECT_EQ(report.active_voxels, v.size());
}

TEST(Reconstruction, FmartImprovesOnMlosAndFindsParticles) {
  ReconstructionReport mlos_report, fmart_report;
  const double q_mlos = recon_test::quality(run("mlos", small_case(), mlos_report), small_truth());
  const SparseVolume v = run("fmart", small_case(), fmart_report);
  const double q_fmart = recon_test::quality(v, small_truth());
  EXPECT_GT(q_fmart, q_mlos + 0.2) << "MLOS Q " << q_mlos;
  EXPECT_GT(q_fmart, 0.90);
  const Vec3d err = median_centroid_error(v, small_case().particles);
  EXPECT_LT(err.x, 0.15);
  EXPECT_LT(err.y, 0.15);
  EXPECT_LT(err.z, 0.2);
  // The report is complete and the projection residual falls.
  ASSERT_EQ(fmart_report.history.size(), 6u);
  EXPECT_EQ(fmart_report.iterations, 6);
  EXPECT_LT(fmart_report.history.back().residual, fmart_report.history[1].residual);
  EXPECT_GT(fmart_report.peak_rss_mb, 0.0);
  EXPECT_GT(fmart_report.active_voxels, 0u);
}

TEST(Reconstruction, SmartReachesFmartQuality) {
  ReconstructionReport report;
  const double q = recon_test::quality(run("smart", small_case(), report, 10), small_truth());
  EXPECT_GT(q, 0.90);
  EXPECT_EQ(report.algorithm, "smart");
}

TEST(Reconstruction, OneAndTwoThreadsAgree) {
  ReconstructionReport r1, r2;
  const SparseVolume a = run("fmart", small_case(), r1, 3, 1);
  const SparseVolume b = run("fmart", small_case(), r2, 3, 2);
  ASSERT_EQ(a.index, b.index);
  double worst = 0, peak = 0;
  for (std::size_t n = 0; n < a.size(); ++n) {
    worst = std::max(worst, static_cast<double>(std::fabs(a.intensity[n] - b.intensity[n])));
    peak = std::max(peak, static_cast<double>(a.intensity[n]));
  }
  EXPECT_LT(worst, 1e-3 * peak);  // only the summation order of the projections differs
}

// A reconstructor keeps its buffers between runs (the exposures and sets of `tomorig process`):
// whatever ran before, each input must give exactly the volume a fresh reconstructor gives it,
// including a larger support after a smaller one (the buffers grow) and the reverse.
TEST(Reconstruction, AReusedReconstructorGivesEachInputTheVolumeOfAFreshOne) {
  static const recon_test::ReducedCase denser = recon_test::make_case(128, 40, 140, 0.08, 11);
  for (const std::string algorithm : {"fmart", "smart"}) {
    ReconstructionOptions o;
    o.algorithm = algorithm;
    o.max_iterations = 4;
    o.threads = 2;
    const std::unique_ptr<recon::Reconstructor> reused = recon::make_reconstructor(o);
    for (const recon_test::ReducedCase* rc : {&small_case(), &denser, &small_case()}) {
      ReconstructionReport r_reused, r_fresh;
      const SparseVolume a = reused->reconstruct(rc->input(), r_reused);
      const SparseVolume b = recon::make_reconstructor(o)->reconstruct(rc->input(), r_fresh);
      EXPECT_EQ(r_reused.active_voxels, r_fresh.active_voxels) << algorithm;
      ASSERT_GT(a.size(), 0u);
      EXPECT_EQ(a.index, b.index) << algorithm;
      EXPECT_EQ(a.intensity, b.intensity) << algorithm;
    }
  }
}

TEST(Reconstruction, StopsOnMeanUpdateThreshold) {
  ReconstructionOptions o;
  o.max_iterations = 50;
  o.stop_mean_update = 0.2;
  ReconstructionReport report;
  recon::make_reconstructor(o)->reconstruct(small_case().input(), report);
  EXPECT_LT(report.iterations, 50);
  EXPECT_LT(report.history.back().mean_update, 0.2);
  for (std::size_t n = 0; n + 1 < report.history.size(); ++n) EXPECT_GE(report.history[n].mean_update, 0.2);
}

TEST(Reconstruction, MartOnATinyCaseConvergesToTheParticles) {
  // 5 particles in 24 x 24 x 12 voxels, 40 px cameras.
  recon_test::ReducedCase rc = recon_test::make_case(24, 12, 40, 0.003);
  ASSERT_EQ(rc.particles.size(), 5u);
  const DenseVolume truth = recon_test::truth_volume(rc.grid, rc.particles);
  ReconstructionReport mart_report, mlos_report;
  const SparseVolume v = run("mart", rc, mart_report, 10);
  const double q_mart = recon_test::quality(v, truth);
  const double q_mlos = recon_test::quality(run("mlos", rc, mlos_report), truth);
  EXPECT_GT(q_mart, 0.9);
  EXPECT_GT(q_mart, q_mlos);
  EXPECT_LT(mart_report.history.back().residual, 0.5 * mart_report.history.front().residual);
  const Vec3d err = median_centroid_error(v, rc.particles);
  EXPECT_LT(err.x, 0.2);
  EXPECT_LT(err.y, 0.2);
  EXPECT_LT(err.z, 0.3);
}

}  // namespace
