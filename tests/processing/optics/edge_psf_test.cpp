// The knife-edge PSF (thesis Sect. 6.4) against the spray-thesis simulator's PSF truth: an outer
// and an inner camera at every one of the 13 calibration depths (0.75 mm apart), chi recovered
// within 5 % (all four cameras go through the CLI in tests/apps/optics_cli_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/edge_psf.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::optics {
namespace {

TEST(EdgePsf, GaussianFitReturnsTheHalfWidth) {
  std::vector<double> x, y;
  for (double v = -6; v <= 6; v += 0.25) {
    x.push_back(v);
    y.push_back(3.0 * std::exp(-2.0 * (v - 0.3) * (v - 0.3) / (1.7 * 1.7)) + 0.1);
  }
  double rms = 1;
  EXPECT_NEAR(fit_line_spread_chi(x, y, &rms), 1.7, 1e-6);
  EXPECT_LT(rms, 1e-6);
  EXPECT_THROW(fit_line_spread_chi({1, 2}, {1, 2}), Error);
}

TEST(EdgePsf, RecoversTheSimulatedHalfWidthAtEveryDepthWithin5Percent) {
  sim::SprayOptions o;
  o.reduced = true;
  o.seed = 21;
  const sim::SprayCase c = sim::make_spray_thesis_case(o);
  double worst = 0;
  for (std::size_t ci : {std::size_t{0}, std::size_t{2}}) {  // cam1 (-45 deg, f 105), cam3 (+25 deg, f 200)
    const sim::SprayCamera& cam = c.cameras[ci];
    for (std::size_t k = 0; k < cam.chi.size(); ++k) {
      const double z = cam.chi[k].z_mm;
      const Image img = sim::render_spray_edge_target(c, ci, z, k);
      const EdgePsf psf = measure_edge_psf(img);
      ASSERT_GE(psf.edges.size(), 4u) << cam.id << " z " << z;
      // Pixels to object um at this depth (the camera's magnification there).
      const double object_pixel_um = cam.pixel_pitch_um / cam.pinhole.magnification({0, 0, z}, cam.pixel_pitch_um);
      const double chi_um = psf.chi_px * object_pixel_um;
      const double error = chi_um / cam.chi[k].chi_um - 1.0;
      worst = std::max(worst, std::abs(error));
      EXPECT_LT(std::abs(error), 0.05) << cam.id << " z " << z << ": " << chi_um << " um, truth " << cam.chi[k].chi_um;
    }
  }
  std::printf("worst chi error over 2 cameras x 13 depths: %.2f %%\n", 100 * worst);
}

TEST(EdgePsf, RefusesAnImageWithoutEdges) {
  Image flat = Image::allocate(200, 100, SampleType::f32);
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x) flat.at<float>(x, y) = 1000.0f;
  EXPECT_THROW(measure_edge_psf(flat), Error);
}

}  // namespace
}  // namespace tomorig::optics
