// The volume deformation of the deformation passes (volume_deformation.h) against analytic
// references: the cubic B-spline through the coefficients passes through the samples (zero
// displacement gives the samples back, at the borders too), a constant sub-voxel displacement
// moves a smooth field by exactly that much, and the largest magnitude that deform_pair reports
// is the one of what it wrote (the listing's threshold comes from it). The volumes are small
// and of odd sizes: rows not a multiple of the prefilter's 8 lines, the last tile of rows
// partial, the prefetches of the next row reaching past the volume's end.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "correlation/volume_deformation.h"
#include "correlation/volume_view.h"

namespace {

using namespace tomorig;
using namespace tomorig::piv;
using detail::VolumeView;

struct Volume {
  int nx, ny, nz;
  std::vector<float> values;
  VolumeView view() const { return {values.data(), nx, ny, nz}; }
  std::size_t linear(int i, int j, int k) const {
    return i + static_cast<std::size_t>(nx) * (j + static_cast<std::size_t>(ny) * k);
  }
};

// A predictor of the same displacement d (voxels) at every node, covering the volume.
VectorField constant_predictor(const Volume& v, Vec3f d) {
  VectorField f(3, 3, 3);
  f.origin = {0.0, 0.0, 0.0};
  f.spacing = {(v.nx - 1) / 2.0, (v.ny - 1) / 2.0, (v.nz - 1) / 2.0};
  for (auto& value : f.displacement) value = d;
  return f;
}

// Sparse particle-like samples (most voxels 0, some bright, a few negative).
Volume particles(int nx, int ny, int nz, unsigned seed) {
  Volume v{nx, ny, nz, std::vector<float>(static_cast<std::size_t>(nx) * ny * nz, 0.0f)};
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (float& value : v.values) {
    const float u = uniform(random);
    if (u < 0.08f) value = 0.2f + uniform(random);
    else if (u < 0.09f) value = -(0.2f + uniform(random));
  }
  return v;
}

// A smooth field: a few broad Gaussians (sigma 3 voxels), at any real position.
double smooth_at(double x, double y, double z) {
  const double centres[3][3] = {{9.3, 7.1, 6.2}, {20.5, 14.8, 9.7}, {14.2, 20.3, 4.9}};
  double sum = 0;
  for (const auto& c : centres) {
    const double r2 = (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2]);
    sum += std::exp(-r2 / (2 * 3.0 * 3.0));
  }
  return sum;
}

TEST(Deformation, ZeroDisplacementGivesTheSamplesBackBordersIncluded) {
  const Volume a = particles(29, 21, 11, 3u), b = particles(29, 21, 11, 4u);
  std::vector<float> coef_a, coef_b, out_a, out_b;
  detail::bspline_coefficients(a.view(), 2, coef_a);
  detail::bspline_coefficients(b.view(), 2, coef_b);
  const VolumeView ca{coef_a.data(), a.nx, a.ny, a.nz}, cb{coef_b.data(), b.nx, b.ny, b.nz};
  detail::deform_pair(ca, cb, constant_predictor(a, {0, 0, 0}), 1, Interpolation::cubic_bspline, out_a, out_b, 2);
  ASSERT_EQ(out_a.size(), a.values.size());
  for (std::size_t n = 0; n < a.values.size(); ++n) {
    ASSERT_NEAR(out_a[n], a.values[n], 2e-5) << "voxel " << n;
    ASSERT_NEAR(out_b[n], b.values[n], 2e-5) << "voxel " << n;
  }
}

TEST(Deformation, ConstantSubVoxelDisplacementMovesASmoothFieldByHalfOfItEachWay) {
  Volume v{30, 27, 14, {}};
  v.values.resize(static_cast<std::size_t>(v.nx) * v.ny * v.nz);
  for (int k = 0; k < v.nz; ++k)
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i) v.values[v.linear(i, j, k)] = static_cast<float>(smooth_at(i, j, k));
  std::vector<float> coef, out_a, out_b;
  detail::bspline_coefficients(v.view(), 2, coef);
  const VolumeView c{coef.data(), v.nx, v.ny, v.nz};
  const Vec3f d{0.74f, -1.22f, 0.46f};
  detail::deform_pair(c, c, constant_predictor(v, d), 1, Interpolation::cubic_bspline, out_a, out_b, 2);
  // Eq. 2.17: out_a(x) = v(x - d/2), out_b(x) = v(x + d/2); away from the mirrored borders.
  double worst = 0;
  for (int k = 3; k < v.nz - 3; ++k)
    for (int j = 3; j < v.ny - 3; ++j)
      for (int i = 3; i < v.nx - 3; ++i) {
        const std::size_t n = v.linear(i, j, k);
        worst = std::max(worst, std::abs(out_a[n] - smooth_at(i - d.x / 2, j - d.y / 2, k - d.z / 2)));
        worst = std::max(worst, std::abs(out_b[n] - smooth_at(i + d.x / 2, j + d.y / 2, k + d.z / 2)));
      }
  EXPECT_LT(worst, 2e-3);  // cubic interpolation of Gaussians of sigma 3 voxels (peak 1)
}

TEST(Deformation, ReportsTheLargestMagnitudeOfWhatItWrote) {
  Volume a = particles(37, 19, 13, 5u), b = particles(37, 19, 13, 6u);
  // The brightest voxel of each is negative: the magnitude is what counts.
  a.values[a.linear(18, 9, 6)] = -3.0f;
  b.values[b.linear(20, 8, 7)] = -3.0f;
  std::vector<float> coef_a, coef_b, out_a, out_b;
  detail::bspline_coefficients(a.view(), 2, coef_a);
  detail::bspline_coefficients(b.view(), 2, coef_b);
  std::vector<std::uint8_t> support_a, support_b, scratch;
  detail::signal_support(a.view(), detail::kSupportThreshold, detail::largest_magnitude(a.view(), 2),
                         detail::kSupportRadius, 2, support_a, scratch);
  detail::signal_support(b.view(), detail::kSupportThreshold, detail::largest_magnitude(b.view(), 2),
                         detail::kSupportRadius, 2, support_b, scratch);
  const VolumeView ca{coef_a.data(), a.nx, a.ny, a.nz}, cb{coef_b.data(), b.nx, b.ny, b.nz};
  const detail::DeformedLargest largest =
      detail::deform_pair(ca, cb, constant_predictor(a, {1.37f, -0.61f, 0.83f}), 1, Interpolation::cubic_bspline, out_a,
                          out_b, 2, support_a, support_b);
  auto largest_of = [](const std::vector<float>& values) {
    float m = 0.0f;
    for (float value : values) m = std::max(m, std::abs(value));
    return m;
  };
  // (The negative voxel stays the largest magnitude after the move: the test would notice a
  // largest that forgot the sign.)
  EXPECT_GT(largest_of(out_a), *std::max_element(out_a.begin(), out_a.end()));
  EXPECT_GT(largest_of(out_b), *std::max_element(out_b.begin(), out_b.end()));
  EXPECT_EQ(largest.a, largest_of(out_a));
  EXPECT_EQ(largest.b, largest_of(out_b));
  EXPECT_EQ(detail::largest_magnitude({out_a.data(), a.nx, a.ny, a.nz}, 2), largest_of(out_a));
}

}  // namespace
