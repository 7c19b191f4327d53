// The size-thesis-spray case (../shared/benchmarks/README.md; thesis Sect. 6.5, Table 6.1):
// its definition, and its geometry checked with the pinhole projection written out here (Eq.
// 3.12 rotation, t = (0, 0, D)), not with the simulator's own camera code.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/simulated_rig.h"

namespace {

using namespace tomorig;

struct Pixel {
  double u, v;
};

// World mm -> pixel for a camera yawed by yaw_deg about y, looking at the origin from D.
Pixel project(const sim::SimulatedCameraSpec& cam, const Vec3d& x) {
  const double phi = cam.yaw_deg * std::numbers::pi / 180.0, c = std::cos(phi), s = std::sin(phi);
  const double xc = c * x.x - s * x.z, yc = x.y, zc = s * x.x + c * x.z + cam.distance_mm;
  const double f = cam.focal_length_mm / (cam.pixel_pitch_um * 1e-3);
  return {f * xc / zc + (cam.width - 1) * 0.5, f * yc / zc + (cam.height - 1) * 0.5};
}

TEST(SizeThesisSprayCase, HasTheThesisCamerasAndGrid) {
  const sim::CaseDefinition& c = sim::find_case("size-thesis-spray");
  ASSERT_EQ(c.cameras.size(), 4u);
  const double yaws[] = {45, 15, -15, -45};
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(c.cameras[i].yaw_deg, yaws[i]);
    EXPECT_EQ(c.cameras[i].width, 1600);
    EXPECT_EQ(c.cameras[i].height, 1200);
    EXPECT_DOUBLE_EQ(c.cameras[i].pixel_pitch_um, 7.4);
  }
  EXPECT_EQ(c.grid.nx, 1080);
  EXPECT_EQ(c.grid.ny, 1020);
  EXPECT_EQ(c.grid.nz, 540);
  EXPECT_NEAR(c.grid.voxel_size, 1.0 / 60.0, 1e-12);  // 60 voxel/mm
  // Centred on the origin: 18 x 17 x 9 mm.
  const Vec3d lo = c.grid.centre_of(-0.5, -0.5, -0.5), hi = c.grid.centre_of(1079.5, 1019.5, 539.5);
  EXPECT_NEAR(lo.x, -9.0, 1e-9);
  EXPECT_NEAR(hi.x, 9.0, 1e-9);
  EXPECT_NEAR(lo.y, -8.5, 1e-9);
  EXPECT_NEAR(hi.z, 4.5, 1e-9);
  EXPECT_DOUBLE_EQ(c.sigma_px, 0.75);  // 4 sigma = 3 px
}

TEST(SizeThesisSprayCase, MagnificationIsAboutPoint44SoOnePixelSeesOneVoxel) {
  for (const auto& cam : sim::find_case("size-thesis-spray").cameras) {
    // y is perpendicular to every yaw: 1 mm along y at the origin spans magnification / pitch px.
    const Pixel a = project(cam, {0, -0.5, 0}), b = project(cam, {0, 0.5, 0});
    const double magnification = (b.v - a.v) * cam.pixel_pitch_um * 1e-3;
    EXPECT_NEAR(magnification, 0.44, 0.01) << cam.id;
    EXPECT_NEAR((b.v - a.v) / 60.0, 1.0, 0.01) << cam.id << ": px per voxel";
  }
}

TEST(SizeThesisSprayCase, EveryCameraSeesTheWholeGrid) {
  const sim::CaseDefinition& c = sim::find_case("size-thesis-spray");
  const sim::SimulatedRig rig(sim::SimulationOptions{.case_name = c.name});
  ASSERT_EQ(rig.cameras().size(), 4u);
  for (std::size_t n = 0; n < 4; ++n) {
    const auto& cam = c.cameras[n];
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3d x = c.grid.centre_of(corner & 1 ? 1079 : 0, corner & 2 ? 1019 : 0, corner & 4 ? 539 : 0);
      const Pixel p = project(cam, x);
      EXPECT_GT(p.u, 0.0) << cam.id << " corner " << corner;
      EXPECT_LT(p.u, cam.width - 1.0) << cam.id << " corner " << corner;
      EXPECT_GT(p.v, 0.0) << cam.id << " corner " << corner;
      EXPECT_LT(p.v, cam.height - 1.0) << cam.id << " corner " << corner;
      // The simulator's camera model agrees with the projection written out here.
      const Vec2d q = rig.cameras()[n].model.project(x);
      EXPECT_NEAR(q.x, p.u, 1e-6);
      EXPECT_NEAR(q.y, p.v, 1e-6);
    }
  }
  // 0.03 ppp of 1600 x 1200 px.
  sim::SimulationOptions o;
  o.case_name = c.name;
  o.ppp = 0.03;
  EXPECT_EQ(sim::SimulatedRig(o).particles_per_set(), 57600u);
}

}  // namespace
