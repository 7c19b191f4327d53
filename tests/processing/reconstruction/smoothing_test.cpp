// Gaussian post-smoothing of sparse volumes against a brute-force dense convolution.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "tomorig/core/error.h"
#include "tomorig/processing/reconstruction/smoothing.h"

namespace tomorig::recon {
namespace {

SparseVolume three_voxels(const VoxelGrid& g) {
  SparseVolume v;
  v.grid = g;
  for (const auto& [i, j, k, value] : {std::tuple{3, 4, 2, 2.0f}, std::tuple{10, 10, 5, 1.0f}, std::tuple{0, 0, 0, 4.0f}}) {
    v.index.push_back(static_cast<std::uint32_t>(g.linear(i, j, k)));
    v.intensity.push_back(value);
  }
  std::sort(v.index.begin(), v.index.end());  // values are re-attached below in index order
  v.intensity = {4.0f, 2.0f, 1.0f};
  return v;
}

// Dense reference: sum over voxels of value * normalised separable Gaussian taps (3 sigma).
double reference(const SparseVolume& v, const Vec3d& s, int i, int j, int k) {
  auto taps = [](double sigma, int d) {
    if (sigma < 0.25) return d == 0 ? 1.0 : 0.0;
    const int r = static_cast<int>(std::ceil(3 * sigma));
    if (std::abs(d) > r) return 0.0;
    double sum = 0;
    for (int x = -r; x <= r; ++x) sum += std::exp(-0.5 * x * x / (sigma * sigma));
    return std::exp(-0.5 * d * d / (sigma * sigma)) / sum;
  };
  const VoxelGrid& g = v.grid;
  double acc = 0;
  for (std::size_t n = 0; n < v.size(); ++n) {
    const int vi = static_cast<int>(v.index[n] % g.nx), vj = static_cast<int>((v.index[n] / g.nx) % g.ny),
              vk = static_cast<int>(v.index[n] / (static_cast<std::size_t>(g.nx) * g.ny));
    acc += v.intensity[n] * taps(s.x, i - vi) * taps(s.y, j - vj) * taps(s.z, k - vk);
  }
  return acc;
}

TEST(GaussianSmooth, MatchesDenseConvolutionIncludingGridEdges) {
  const VoxelGrid g{16, 14, 8, {0, 0, 0}, 1.0};
  const SparseVolume v = three_voxels(g);
  for (const Vec3d s : {Vec3d{0.68, 0.68, 0.1}, Vec3d{1.0, 0.5, 0.8}}) {
    const DenseVolume got = gaussian_smooth(v, s, 2).to_dense();
    for (int k = 0; k < g.nz; ++k)
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) ASSERT_NEAR(got.at(i, j, k), reference(v, s, i, j, k), 1e-6) << i << j << k;
  }
}

TEST(GaussianSmooth, ConservesIntensityAwayFromEdgesAndKeepsCentroids) {
  const VoxelGrid g{20, 20, 10, {0, 0, 0}, 1.0};
  SparseVolume v;
  v.grid = g;
  v.index = {static_cast<std::uint32_t>(g.linear(9, 11, 5))};
  v.intensity = {3.0f};
  const SparseVolume s = gaussian_smooth(v, {0.68, 0.68, 0.1});
  double total = 0, cx = 0, cy = 0;
  for (std::size_t n = 0; n < s.size(); ++n) {
    total += s.intensity[n];
    cx += s.intensity[n] * static_cast<double>(s.index[n] % 20);
    cy += s.intensity[n] * static_cast<double>((s.index[n] / 20) % 20);
  }
  EXPECT_NEAR(total, 3.0, 1e-5);
  EXPECT_NEAR(cx / total, 9.0, 1e-6);
  EXPECT_NEAR(cy / total, 11.0, 1e-6);
  EXPECT_GT(s.size(), 9u);  // spread over the xy neighbourhood
  EXPECT_TRUE(std::is_sorted(s.index.begin(), s.index.end()));
}

TEST(GaussianSmooth, ZeroSigmaIsIdentityAndBadSigmaIsRefused) {
  const VoxelGrid g{16, 14, 8, {0, 0, 0}, 1.0};
  const SparseVolume v = three_voxels(g);
  const SparseVolume same = gaussian_smooth(v, {0, 0, 0});
  EXPECT_EQ(same.index, v.index);
  EXPECT_EQ(same.intensity, v.intensity);
  EXPECT_THROW(gaussian_smooth(v, {-1, 0, 0}), Error);
  EXPECT_THROW(gaussian_smooth(v, {NAN, 0, 0}), Error);
}

}  // namespace
}  // namespace tomorig::recon
