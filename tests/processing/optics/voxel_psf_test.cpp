// The knife-edge PSF in voxel space (thesis Sect. 6.4) against the spray-thesis simulator's
// PSF truth: chessboard images rendered at each camera's chi(z), back-projected onto voxel
// planes through the true camera, flat-fielded and measured; chi recovered within 5 % at every
// one of the 13 depths (all four cameras go through `tomorig optics psf` in
// tests/apps/optics_cli_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/voxel_psf.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::optics {
namespace {

// +-4 mm around the axis at about 1 voxel per pixel, as the thesis's 60 voxel/mm.
VoxelPlane centre_plane(const sim::SprayCamera& cam, double z_mm, double voxels_per_pixel = 1.0) {
  const double voxel = cam.pixel_pitch_um / cam.magnification / 1000.0 / voxels_per_pixel;
  const int n = static_cast<int>(10.0 / voxel);
  return {-0.5 * (n - 1) * voxel, -0.5 * (n - 1) * voxel, z_mm, voxel, n, n};
}

TEST(VoxelPsf, RecoversTheSimulatedHalfWidthAtEveryDepthWithin5Percent) {
  sim::SprayOptions o;
  o.reduced = true;
  o.seed = 23;
  const sim::SprayCase c = sim::make_spray_thesis_case(o);
  double worst = 0;
  for (std::size_t ci : {std::size_t{2}}) {  // cam3 (+25 deg, f 200): the CLI test checks all four
    const sim::SprayCamera& cam = c.cameras[ci];
    for (std::size_t k = 0; k < cam.chi.size(); ++k) {
      const double z = cam.chi[k].z_mm;
      const Image img = sim::render_spray_chessboard_target(c, ci, z, k);
      const VoxelPsf psf = measure_voxel_psf(img, cam.pinhole, centre_plane(cam, z));
      EXPECT_GE(psf.edges, 8) << cam.id << " z " << z;
      // The board's 2 mm squares, in voxels of the plane.
      EXPECT_NEAR(psf.square_voxels * centre_plane(cam, z).voxel_mm, 2.0, 0.1);
      const double error = psf.chi_um / cam.chi[k].chi_um - 1.0;
      worst = std::max(worst, std::abs(error));
      EXPECT_LT(std::abs(error), 0.05) << cam.id << " z " << z << ": " << psf.chi_um << " um, truth "
                                       << cam.chi[k].chi_um << " (in the voxel plane " << psf.chi_voxel_um << ")";
      // Interpolation widens the spread in the plane, never narrows it.
      EXPECT_GT(psf.chi_voxel_um, psf.chi_um);
      std::printf("%s z %5.2f: truth %.1f, measured %.1f (voxel plane %.1f) um, %d edges\n", cam.id.c_str(), z,
                  cam.chi[k].chi_um, psf.chi_um, psf.chi_voxel_um, psf.edges);
    }
  }
  std::printf("worst chi error over 13 depths: %.2f %%\n", 100 * worst);
}

TEST(VoxelPsf, FinerVoxelsGiveTheSameCameraPsf) {
  // Bilinear back-projection spreads by a tent of the camera's pixels, whatever the voxel: at
  // 2 voxel/pixel the plane's spread and the camera PSF behind it are those of 1 voxel/pixel
  // (the thesis found 11 % less spread at 2 voxel/pixel, Sect. 6.4; docs/spray.md).
  sim::SprayOptions o;
  o.reduced = true;
  const sim::SprayCase c = sim::make_spray_thesis_case(o);
  const sim::SprayCamera& cam = c.cameras[1];
  const Image img = sim::render_spray_chessboard_target(c, 1, 0.0, 0);
  const VoxelPsf one = measure_voxel_psf(img, cam.pinhole, centre_plane(cam, 0.0, 1.0));
  const VoxelPsf two = measure_voxel_psf(img, cam.pinhole, centre_plane(cam, 0.0, 2.0));
  EXPECT_NEAR(two.chi_um / one.chi_um, 1.0, 0.04);
  EXPECT_NEAR(two.chi_voxel_um / one.chi_voxel_um, 1.0, 0.04);
  EXPECT_NEAR(one.chi_um / sim::spray_chi_um(cam, 0.0), 1.0, 0.05);
}

TEST(VoxelPsf, AcrossTheOtherLinesThePlaneStretchesButTheCameraPsfIsTheSame) {
  // cam1 looks 45 deg off the z axis about y: along x the plane is foreshortened by cos 45,
  // so the back-projected spread is about 1.4 x wider there; the camera's PSF is not.
  sim::SprayOptions o;
  o.reduced = true;
  o.seed = 5;
  const sim::SprayCase c = sim::make_spray_thesis_case(o);
  const sim::SprayCamera& cam = c.cameras[0];
  for (double z : {0.0, 4.5}) {
    const Image img = sim::render_spray_chessboard_target(c, 0, z, 0);
    const VoxelPsf x = measure_voxel_psf(img, cam.pinhole, centre_plane(cam, z), SpreadAxis::x);
    EXPECT_NEAR(x.chi_um / sim::spray_chi_um(cam, z), 1.0, 0.05) << "z " << z;
    EXPECT_GT(x.chi_voxel_um, 1.25 * x.chi_um) << "z " << z;
  }
}

TEST(VoxelPsf, RefusesAPlaneOutsideTheImageAndAPlaneWithoutABoard) {
  sim::SprayOptions o;
  o.reduced = true;
  o.noise = false;
  const sim::SprayCase c = sim::make_spray_thesis_case(o);
  const sim::SprayCamera& cam = c.cameras[0];
  const Image board = sim::render_spray_chessboard_target(c, 0, 0.0, 0);
  VoxelPlane far = centre_plane(cam, 0.0);
  far.x0_mm = 40.0;
  EXPECT_THROW(measure_voxel_psf(board, cam.pinhole, far), Error);
  const Image bright = sim::render_bright_field(c, 0, 0);
  try {
    measure_voxel_psf(bright, cam.pinhole, centre_plane(cam, 0.0));
    FAIL() << "a bright field has no edges";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no chessboard"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::optics
