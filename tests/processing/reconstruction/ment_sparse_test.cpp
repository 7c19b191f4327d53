// The sparse MENT (precomputed sample list of the support) against the dense reference MENT
// (a full lattice sweep per camera update) on a tiny case, and MENT's accuracy against the
// simulator's truth at the thesis's MENT density limit (0.05 ppp, Q >= 0.75 in the thesis).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "../../../processing/src/reconstruction/ment_reference.h"  // a test oracle, private to processing

namespace {

using namespace tomorig;
using recon::ReconstructionOptions;
using recon::ReconstructionReport;

ReconstructionOptions ment_options(int iterations, int threads) {
  ReconstructionOptions o;
  o.algorithm = "ment";
  o.max_iterations = iterations;
  o.threads = threads;
  return o;
}

TEST(MentSparse, EqualsTheDenseReferenceOnATinyCase) {
  // 40 x 40 x 16 voxels, 48 px cameras, 0.03 ppp (69 particles).
  const recon_test::ReducedCase rc = recon_test::make_case(40, 16, 48, 0.03, 11);
  ReconstructionReport sparse_report, dense_report;
  const SparseVolume sparse = recon::make_reconstructor(ment_options(3, 2))->reconstruct(rc.input(), sparse_report);
  const SparseVolume dense =
      recon::make_ment_dense_reference(ment_options(3, 1))->reconstruct(rc.input(), dense_report);
  ASSERT_FALSE(dense.index.empty());

  // Positions are quantised to 1/256 px in the sparse list, so values differ by rounding only;
  // voxels whose product is a rounding away from zero may be in one result and not the other.
  float peak = 0.0f;
  for (float x : dense.intensity) peak = std::max(peak, x);
  std::size_t n = 0, m = 0, matched = 0, only_one = 0;
  double worst = 0.0;
  while (n < sparse.size() || m < dense.size()) {
    if (m == dense.size() || (n < sparse.size() && sparse.index[n] < dense.index[m])) {
      worst = std::max(worst, static_cast<double>(sparse.intensity[n++]));
      ++only_one;
    } else if (n == sparse.size() || dense.index[m] < sparse.index[n]) {
      worst = std::max(worst, static_cast<double>(dense.intensity[m++]));
      ++only_one;
    } else {
      worst = std::max(worst, std::fabs(static_cast<double>(sparse.intensity[n++]) - dense.intensity[m++]));
      ++matched;
    }
  }
  std::printf("sparse %zu voxels, dense %zu, matched %zu, worst difference %.2e of peak %.3f\n", sparse.size(),
              dense.size(), matched, worst, peak);
  EXPECT_GT(matched, 100u);
  EXPECT_LE(only_one, matched / 100 + 1);
  EXPECT_LT(worst, 0.01 * peak);

  ASSERT_EQ(sparse_report.history.size(), dense_report.history.size());
  for (std::size_t i = 0; i < sparse_report.history.size(); ++i)
    EXPECT_NEAR(sparse_report.history[i].residual, dense_report.history[i].residual,
                0.01 * dense_report.history[i].residual)
        << "iteration " << i + 1;
}

TEST(MentSparse, ReachesTheThesisQualityAtItsDensityLimit) {
  // 128 x 128 x 40 voxels seen by 140 px cameras at 0.05 ppp: the thesis's MENT reaches
  // Q = 0.75 at this density on the full case (Sect. 3.3.1).
  const recon_test::ReducedCase rc = recon_test::make_case(128, 40, 140, 0.05, 7);
  const DenseVolume truth = recon_test::truth_volume(rc.grid, rc.particles);
  ReconstructionReport report;
  const SparseVolume v = recon::make_reconstructor(ment_options(4, 0))->reconstruct(rc.input(), report);
  const double q = recon_test::quality(v, truth);
  std::printf("reduced case 0.05 ppp: Q MENT (4 it.) %.3f, %.3f s\n", q, report.seconds);
  EXPECT_GE(q, 0.75);
  EXPECT_EQ(report.iterations, 4);
}

}  // namespace
