// The MLOS support scan (support_scan.h): its AVX-512 and scalar reach passes, and the
// slice-block order of MLOS and MENT, against references that do not share that code.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "../../../processing/src/reconstruction/grid_projector.h"
#include "../../../processing/src/reconstruction/mlos.h"
#include "../../../processing/src/reconstruction/prepared_input.h"
#include "../../../processing/src/reconstruction/support_scan.h"

namespace {

using namespace tomorig;

// 21 slices: not a multiple of the 8-slice blocks, so the last block is partial.
const recon_test::ReducedCase& scan_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(80, 21, 100, 0.05, 7);
  return rc;
}

recon::detail::ActiveSet mlos_of(const recon::detail::PreparedInput& in, double threshold) {
  const recon::detail::GridProjector projector(in);
  recon::detail::MlosSettings settings;
  settings.threshold = threshold;
  return recon::detail::run_mlos(in, projector, settings);
}

TEST(SupportScan, VectorAndScalarReachPassesGiveTheSameSupport) {
  recon::ReconstructionOptions options;
  const recon::detail::PreparedInput in = recon::detail::prepare_input(scan_case().input(), options);
  for (double threshold : {0.05, 0.15}) {
    recon::detail::allow_vector_reach_pass(true);
    const recon::detail::ActiveSet vector = mlos_of(in, threshold);
    recon::detail::allow_vector_reach_pass(false);
    const recon::detail::ActiveSet scalar = mlos_of(in, threshold);
    recon::detail::allow_vector_reach_pass(true);
    ASSERT_GT(scalar.size(), 1000u);
    EXPECT_EQ(vector.index, scalar.index);
    EXPECT_EQ(vector.value, scalar.value);
  }
}

// Reference: every voxel, positions from GridProjector::row, each camera read bilinearly on
// the thresholded image (no reach mask, no coarse blocks, no vector code).
std::vector<std::uint32_t> per_voxel_support(const recon::detail::PreparedInput& in, double threshold) {
  const VoxelGrid& g = in.grid;
  const recon::detail::GridProjector projector(in);
  std::vector<recon::detail::ThresholdedImage> images;
  for (const recon::detail::CameraImage& im : in.images) images.emplace_back(im, threshold);
  std::vector<float> u(static_cast<std::size_t>(g.nx)), v(static_cast<std::size_t>(g.nx));
  std::vector<int> lit(g.voxel_count(), 1);
  for (std::size_t c = 0; c < in.camera_count(); ++c)
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j) {
        projector.row(c, j, k, u.data(), v.data());
        for (int i = 0; i < g.nx; ++i) {
          const std::size_t n = g.linear(i, j, k);
          const float s = images[c].read(u[static_cast<std::size_t>(i)], v[static_cast<std::size_t>(i)]);
          lit[n] = lit[n] && s > 0.0f;
        }
      }
  std::vector<std::uint32_t> expected;
  for (std::size_t n = 0; n < lit.size(); ++n)
    if (lit[n]) expected.push_back(static_cast<std::uint32_t>(n));
  return expected;
}

TEST(SupportScan, SupportIsAscendingAndEqualsAPerVoxelTest) {
  recon::ReconstructionOptions options;
  const recon::detail::PreparedInput in = recon::detail::prepare_input(scan_case().input(), options);
  const double threshold = 0.1;
  const recon::detail::ActiveSet set = mlos_of(in, threshold);
  ASSERT_GT(set.size(), 1000u);
  EXPECT_TRUE(std::is_sorted(set.index.begin(), set.index.end()));
  EXPECT_EQ(std::adjacent_find(set.index.begin(), set.index.end()), set.index.end());
  EXPECT_EQ(set.index, per_voxel_support(in, threshold));
}

// The coarse 2 x 2 x 2 block test is conservative: with it in play (every camera here has a
// lattice and a small dilation), and on a grid of odd sizes along every axis (blocks of one
// voxel, row or slice at the far faces), the support is still exactly the per-voxel one.
TEST(SupportScan, CoarseBlockTestKeepsExactlyThePerVoxelSupport) {
  recon::ReconstructionInput input = scan_case().input();
  input.grid = VoxelGrid::centred(79, 77, 21, scan_case().grid.voxel_size);
  recon::ReconstructionOptions options;
  const recon::detail::PreparedInput in = recon::detail::prepare_input(input, options);
  const recon::detail::GridProjector projector(in);
  for (double threshold : {0.05, 0.15}) {
    const recon::detail::SupportScanner scanner(in, projector, threshold);
    EXPECT_EQ(scanner.coarse_cameras(), in.camera_count());
    for (const bool vector : {true, false}) {
      recon::detail::allow_vector_reach_pass(vector);
      const recon::detail::ActiveSet set = mlos_of(in, threshold);
      ASSERT_GT(set.size(), 1000u);
      EXPECT_EQ(set.index, per_voxel_support(in, threshold)) << "threshold " << threshold << ", vector " << vector;
    }
    recon::detail::allow_vector_reach_pass(true);
  }
}

}  // namespace
