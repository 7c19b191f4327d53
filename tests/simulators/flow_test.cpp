// Flows and scenes against Eq. 3.13 and the tpiv-thesis grid, written out independently.
#include <cmath>

#include <gtest/gtest.h>

#include "tomorig/simulators/flow.h"
#include "tomorig/simulators/light_sheet.h"
#include "tomorig/simulators/scene.h"
#include "tomorig/simulators/taylor_green.h"

namespace {

using tomorig::Vec3d;
constexpr double kPi = 3.14159265358979323846;

// Eq. 3.13 at a world point of the tpiv-thesis grid (voxel i centred at (i - 255.5) * 0.0195,
// k at (k - 79.5) * 0.0195), A = 5 voxel, p = 256 voxel, returned in mm.
Vec3d eq_3_13_mm(const Vec3d& X) {
  const double x = X.x / 0.0195 + 255.5, z = X.z / 0.0195 + 79.5;
  const double A = 5, p = 256, h = 0.0195;
  return {A * std::sin(2 * kPi * x / p) * std::cos(2 * kPi * z / p) * h,
          -A * std::sin(2 * kPi * x / p) * std::sin(2 * kPi * z / p) * h,
          -A * std::cos(2 * kPi * x / p) * std::sin(2 * kPi * z / p) * h};
}

TEST(TaylorGreen, MatchesEquation313) {
  const tomorig::sim::TaylorGreenFlow flow(tomorig::VoxelGrid::centred(512, 512, 160, 0.0195), 5, 256);
  const tomorig::sim::Slab slab{{-5, -5, -1.5}, {5, 5, 1.5}};
  for (const Vec3d& X : tomorig::sim::uniform_particles(slab, 5000, 17)) {
    const Vec3d got = flow.displacement(X), want = eq_3_13_mm(X);
    ASSERT_NEAR(got.x, want.x, 1e-12);
    ASSERT_NEAR(got.y, want.y, 1e-12);
    ASSERT_NEAR(got.z, want.z, 1e-12);
  }
  EXPECT_EQ(flow.name(), "taylor-green");
  EXPECT_NE(flow.parameters_json().find("\"A_voxel\":5"), std::string::npos);
  EXPECT_NE(flow.parameters_json().find("\"p_voxel\":256"), std::string::npos);
}

TEST(Straddle, ExposuresAreCentredOnTheSeededPosition) {
  const tomorig::sim::TaylorGreenFlow flow(tomorig::VoxelGrid::centred(512, 512, 160, 0.0195), 5, 256);
  const std::vector<Vec3d> mid{{1, 2, 0.3}, {-4, 0, -1.2}};
  const auto pair = tomorig::sim::straddle(mid, flow);
  for (std::size_t n = 0; n < mid.size(); ++n) {
    const Vec3d d = pair.b[n] - pair.a[n], want = eq_3_13_mm(mid[n]);
    EXPECT_NEAR(d.x, want.x, 1e-12);
    EXPECT_NEAR(d.y, want.y, 1e-12);
    EXPECT_NEAR(d.z, want.z, 1e-12);
    EXPECT_NEAR((pair.a[n].x + pair.b[n].x) / 2, mid[n].x, 1e-12);
  }
}

TEST(Scene, UniformParticlesAreInTheSlabAndSeeded) {
  const tomorig::sim::Slab slab{{-5, -5, -1.5}, {5, 5, 1.5}};
  const auto a = tomorig::sim::uniform_particles(slab, 20000, 1);
  Vec3d mean;
  for (const Vec3d& p : a) {
    ASSERT_TRUE(slab.contains(p));
    mean = mean + p * (1.0 / a.size());
  }
  EXPECT_NEAR(mean.x, 0, 0.1);  // 10 mm / sqrt(12 * 20000) = 0.02 mm standard error
  EXPECT_NEAR(mean.z, 0, 0.03);
  const auto b = tomorig::sim::uniform_particles(slab, 20000, 1);
  const auto c = tomorig::sim::uniform_particles(slab, 20000, 2);
  EXPECT_EQ(a[123].x, b[123].x);
  EXPECT_NE(a[123].x, c[123].x);
}

TEST(LightSheet, Profiles) {
  const tomorig::sim::Slab slab{{-5, -5, -1.5}, {5, 5, 1.5}};
  using tomorig::sim::LightSheet;
  using tomorig::sim::LightSheetProfile;
  EXPECT_EQ(LightSheet::for_slab(LightSheetProfile::uniform, slab).intensity(1.4), 1.0);
  const LightSheet g = LightSheet::for_slab(LightSheetProfile::gaussian, slab);
  EXPECT_NEAR(g.intensity(0), 1.0, 1e-12);
  EXPECT_NEAR(g.intensity(1.5), std::exp(-2.0), 1e-12);  // slab face at 2 sigma
  const LightSheet t = LightSheet::for_slab(LightSheetProfile::tophat, slab);
  EXPECT_NEAR(t.intensity(0), 1.0, 1e-9);
  EXPECT_NEAR(t.intensity(1.5), 0.5, 1e-6);
  EXPECT_LT(t.intensity(2.0), 1e-3);
}

}  // namespace
