// MENT (thesis Sect. 3.1.1) on reduced tpiv-thesis cases, judged against the simulator's true
// particle positions: Q (Eq. 3.14) against Gaussian truth blobs, compared with MLOS on the same
// images; the residual of Eq. 3.3 falls over the iterations; memory stays that of the images and
// the sparse output; bad input is refused as for the other reconstructors.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "tomorig/core/error.h"

namespace {

using namespace tomorig;
using recon::ReconstructionOptions;
using recon::ReconstructionReport;

// 96 x 96 x 32 voxels seen by 110 x 110 px cameras, 0.03 ppp (363 particles).
const recon_test::ReducedCase& ment_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(96, 32, 110, 0.03, 5);
  return rc;
}
const DenseVolume& ment_truth() {
  static const DenseVolume truth = recon_test::truth_volume(ment_case().grid, ment_case().particles);
  return truth;
}

SparseVolume run(const std::string& algorithm, const recon::ReconstructionInput& input, ReconstructionReport& report,
                 int iterations, int threads = 0) {
  ReconstructionOptions o;
  o.algorithm = algorithm;
  o.max_iterations = iterations;
  o.threads = threads;
  return recon::make_reconstructor(o)->reconstruct(input, report);
}

TEST(Ment, ReconstructsAtLeastAsWellAsMlosAndFillsTheReport) {
  ReconstructionReport mlos_report, ment_report;
  const double q_mlos = recon_test::quality(run("mlos", ment_case().input(), mlos_report, 1), ment_truth());
  const SparseVolume v = run("ment", ment_case().input(), ment_report, 3);
  const double q_ment = recon_test::quality(v, ment_truth());
  RecordProperty("q_mlos", std::to_string(q_mlos));
  RecordProperty("q_ment", std::to_string(q_ment));
  std::printf("reduced case 0.03 ppp: Q MLOS %.3f, Q MENT (3 it.) %.3f\n", q_mlos, q_ment);
  EXPECT_GT(q_ment, 0.5);
  EXPECT_GT(q_ment, q_mlos);

  EXPECT_EQ(ment_report.algorithm, "ment");
  EXPECT_EQ(ment_report.iterations, 3);
  ASSERT_EQ(ment_report.history.size(), 3u);
  EXPECT_EQ(ment_report.history[0].iteration, 1);
  EXPECT_EQ(ment_report.active_voxels, v.size());
  EXPECT_EQ(ment_report.nonzero_voxels, v.size());
  EXPECT_GT(ment_report.seconds, 0.0);
  EXPECT_GT(ment_report.peak_rss_mb, 0.0);
  EXPECT_GT(ment_report.threads, 0);
  // Sorted, unique indices inside the grid: the slices were appended in z order.
  for (std::size_t n = 1; n < v.size(); ++n) ASSERT_LT(v.index[n - 1], v.index[n]);
  ASSERT_FALSE(v.index.empty());
  EXPECT_LT(v.index.back(), ment_case().grid.voxel_count());
}

TEST(Ment, IterationsReduceTheResidual) {
  ReconstructionReport report;
  run("ment", ment_case().input(), report, 4);
  ASSERT_EQ(report.history.size(), 4u);
  // Iteration 1 measures the flat start h = 1 (Eq. 3.1); every later one a MENT estimate.
  EXPECT_LT(report.history[1].residual, 0.5 * report.history[0].residual);
  EXPECT_LT(report.history[3].residual, report.history[1].residual);
  EXPECT_LT(report.history[3].mean_update, report.history[1].mean_update);
  for (const auto& h : report.history)
    std::printf("iteration %d: residual %.4f, mean update %.4f\n", h.iteration, h.residual, h.mean_update);
}

TEST(Ment, MemoryIsImagesPlusTheSupportNeverTheDenseVolume) {
  // The same images on a grid 3x deeper than the particle slab: 96 x 96 x 96 voxels, 3.4 MB as
  // a dense float volume. MENT may hold the images, the sample list of the support (16 B per
  // sample for 4 cameras, 2 samples per support voxel, plus its 4 B grid index) and the
  // non-zero output (8 B per voxel): memory that grows with the support, not with the grid.
  recon::ReconstructionInput in = ment_case().input();
  VoxelGrid deep = VoxelGrid::centred(96, 96, 96, in.grid.voxel_size);
  in.grid = deep;
  ReconstructionReport report, mlos_report;
  // Two threads: each thread keeps one accumulator image, so the fixed part grows with them.
  const SparseVolume v = run("ment", in, report, 1, 2);
  run("mlos", in, mlos_report, 1, 2);  // the same support criterion: its size bounds MENT's list
  const double dense_mb = static_cast<double>(deep.voxel_count()) * 4.0 / (1024.0 * 1024.0);
  const double images_mb = 4.0 * (3 + 2) * 112.0 * 112.0 * 4.0 / (1024.0 * 1024.0);
  const double support_mb = 1.05 * static_cast<double>(mlos_report.active_voxels) * (2 * 16 + 4) / (1024.0 * 1024.0);
  const double output_mb = static_cast<double>(v.size()) * 8.0 / (1024.0 * 1024.0);
  EXPECT_LE(report.estimated_memory_mb, images_mb + support_mb + output_mb + 1e-6);
  EXPECT_LT(output_mb, 0.6 * dense_mb);
  EXPECT_LT(static_cast<double>(v.size()), 0.3 * static_cast<double>(deep.voxel_count()));
}

TEST(Ment, RefusesBadInputLikeTheOtherReconstructors) {
  auto expect_bad = [](const recon::ReconstructionInput& in, const std::string& needle) {
    ReconstructionReport report;
    try {
      run("ment", in, report, 2);
      ADD_FAILURE() << "ment accepted the input; expected '" << needle << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  recon::ReconstructionInput in = ment_case().input();
  in.images.pop_back();
  expect_bad(in, "4 camera models (calibration) but 3 images");

  in = ment_case().input();
  in.grid.origin.x += 100.0;  // far off to the side: no camera sees it
  expect_bad(in, "sees none of the grid");

  in = ment_case().input();
  ReconstructionOptions o;
  o.algorithm = "ment";
  o.memory_limit_mb = 0.01;
  ReconstructionReport report;
  try {
    recon::make_reconstructor(o)->reconstruct(in, report);
    ADD_FAILURE() << "ment ran within 0.01 MB";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input) << e.what();
  }
}

}  // namespace
