// The predictor between passes and the multigrid scheme: the 3x3x3 smoothing must keep a
// linear field (no pull of the end nodes towards their neighbours), a linear displacement
// gradient must be measured without bias in the layer next to the boundary, and the
// integer-offset pass of the multigrid scheme runs at most at 50 % overlap when deformation
// passes follow. References are analytic fields, never earlier outputs of the code.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "../../../processing/src/correlation/predictor_filters.h"
#include "tomorig/processing/correlation/correlate.h"
#include "volume_pair.h"

namespace {

using namespace tomorig;
using namespace tomorig::piv;

Vec3f linear_field(int i, int j, int k) {
  return {0.5f + 0.3f * i - 0.2f * k, -1.0f + 0.25f * j, 0.1f * i + 0.15f * j - 0.35f * k};
}

TEST(PredictorSmoothing, KeepsALinearFieldExactlyIncludingTheEndNodes) {
  VectorField f(6, 5, 4);
  for (int k = 0; k < f.nz; ++k)
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) f.displacement[f.linear(i, j, k)] = linear_field(i, j, k);
  detail::smooth_gaussian3(f);
  for (int k = 0; k < f.nz; ++k)
    for (int j = 0; j < f.ny; ++j)
      for (int i = 0; i < f.nx; ++i) {
        const Vec3f want = linear_field(i, j, k), got = f.displacement[f.linear(i, j, k)];
        EXPECT_NEAR(got.x, want.x, 1e-5) << i << "," << j << "," << k;
        EXPECT_NEAR(got.y, want.y, 1e-5) << i << "," << j << "," << k;
        EXPECT_NEAR(got.z, want.z, 1e-5) << i << "," << j << "," << k;
      }
}

TEST(PredictorSmoothing, StillDampsANodeToNodeOscillation) {
  VectorField f(7, 1, 1);
  for (int i = 0; i < f.nx; ++i) f.displacement[i] = {i % 2 ? 1.0f : -1.0f, 0.0f, 0.0f};
  detail::smooth_gaussian3(f);
  for (int i = 1; i + 1 < f.nx; ++i) EXPECT_NEAR(f.displacement[i].x, 0.0f, 1e-6);  // (1 2 1)/4 removes it
}

TEST(CorrelationOptions, MultigridOffsetPassAtMostHalfOverlapBeforeDeformation) {
  const auto with = CorrelationOptions::multigrid({32, 32, 32}, 0.75, 2);
  ASSERT_EQ(with.passes.size(), 4u);
  EXPECT_EQ(with.passes[0].downsample, 2);
  EXPECT_DOUBLE_EQ(with.passes[1].overlap, 0.5);
  EXPECT_FALSE(with.passes[1].deformation);
  EXPECT_DOUBLE_EQ(with.passes[2].overlap, 0.75);
  EXPECT_DOUBLE_EQ(with.passes[3].overlap, 0.75);
  const auto without = CorrelationOptions::multigrid({32, 32, 32}, 0.75, 0);
  ASSERT_EQ(without.passes.size(), 2u);
  EXPECT_DOUBLE_EQ(without.passes[1].overlap, 0.75);  // the final pass keeps the requested overlap
  EXPECT_DOUBLE_EQ(CorrelationOptions::multigrid({32, 32, 32}, 0.25, 1).passes[1].overlap, 0.25);
}

// A uniform displacement gradient (shear and stretch, up to ~1.5 voxel of variation across a
// window): the scheme must measure it in every interior layer, including the one next to the
// boundary, whose windows are deformed with the predictor extrapolated beyond the outer nodes.
TEST(Correlate, LinearGradientHasNoBiasNextToTheBoundary) {
  const VoxelGrid grid = corr_test::test_grid(96, 96, 64);
  const Vec3d centre{47.5, 47.5, 31.5};
  auto truth = [&](const Vec3d& v) {
    const Vec3d r = v - centre;
    return Vec3d{1.2 + 0.05 * r.z + 0.02 * r.x, -0.6 + 0.04 * r.x, 0.8 - 0.03 * r.y + 0.02 * r.z};
  };
  const auto pair = corr_test::make_pair(grid, 10.0 / (16 * 16 * 16), truth, 11);
  CorrelationOptions options = CorrelationOptions::multigrid({16, 16, 16}, 0.75, 2);
  options.weighting = WindowWeighting::gaussian;
  CorrelationReport report;
  const VectorField f = correlate(pair.a, pair.b, options, report);
  // Mean error (bias) per component over the layer next to each face, and RMS over the interior.
  double sum2 = 0;
  std::size_t count = 0;
  Vec3d boundary_bias{};
  std::size_t boundary_count = 0;
  for (int k = 1; k + 1 < f.nz; ++k)
    for (int j = 1; j + 1 < f.ny; ++j)
      for (int i = 1; i + 1 < f.nx; ++i) {
        const std::size_t n = f.linear(i, j, k);
        const Vec3d t = truth(grid.voxel_of({f.origin.x + i * f.spacing.x, f.origin.y + j * f.spacing.y,
                                             f.origin.z + k * f.spacing.z}));
        const Vec3d e{f.displacement[n].x - t.x, f.displacement[n].y - t.y, f.displacement[n].z - t.z};
        sum2 += e.x * e.x + e.y * e.y + e.z * e.z;
        ++count;
        if (k == 1 || k == f.nz - 2) {
          // The z faces: the x component has the z gradient (0.05 voxel per voxel).
          boundary_bias = boundary_bias + Vec3d{k == 1 ? e.x : -e.x, e.y, k == 1 ? e.z : -e.z};
          ++boundary_count;
        }
      }
  ASSERT_GT(boundary_count, 0u);
  const double rms = std::sqrt(sum2 / count);
  const Vec3d bias = boundary_bias * (1.0 / boundary_count);
  std::printf("[ figures  ] linear gradient, 16^3 75 %%, Gaussian, 2 deformation passes: RMS %.4f voxel; "
              "next-to-z-face bias x %.4f z %.4f\n", rms, bias.x, bias.z);
  EXPECT_LT(rms, 0.08);
  EXPECT_LT(std::abs(bias.x), 0.03);
  EXPECT_LT(std::abs(bias.z), 0.03);
}

}  // namespace
