// A droplet's diameter from the light its shadow removes (optics/droplet_size.h): the forward
// model against Eq. 6.4 integrated over the image plane, and the inverse against the forward.
#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/processing/optics/droplet_size.h"
#include "tomorig/processing/optics/transmission.h"

namespace tomorig::optics {
namespace {

VisibilitySetup two_cameras() {
  VisibilitySetup s;
  s.cameras = {{"a", 22.0, 0.85, 0.01, {{0.0, 40.0}}}, {"b", 22.0, 0.95, 0.006, {{0.0, 44.0}}}};
  return s;
}

TEST(DropletSize, RemovedLightIsTheShadowProfileIntegratedOverThePlane) {
  const VisibilitySetup setup = two_cameras();
  const std::vector<double> pixel{30.0, 27.0};
  const DropletSizeModel model(setup, pixel);
  const TransmissionModel transmission(setup.liquid, setup.spectrum);
  for (const double d : {8.0, 20.0, 45.0}) {
    // Eq. 6.4 summed numerically for each camera (its own tau and a PSF blur), in its pixels.
    double expected = 0;
    for (std::size_t c = 0; c < 2; ++c) {
      const double tau =
          transmission.transmission(d, object_numerical_aperture(setup.cameras[c].f_number, setup.cameras[c].magnification));
      const double step = 0.25;
      double depletion = 0;
      for (double r = step / 2; r < 250.0; r += step)
        depletion += (1.0 - shadow_profile(r, d, 40.0, tau)) * 2 * M_PI * r * step;
      expected += depletion / (pixel[c] * pixel[c]) / 2;
    }
    EXPECT_NEAR(model.removed_px(d) / expected, 1.0, 0.01) << d;
  }
}

TEST(DropletSize, DiameterInvertsTheRemovedLight) {
  const DropletSizeModel model(two_cameras(), {30.0, 27.0});
  for (const double d : {1.0, 5.0, 9.7, 14.2, 33.0, 80.0, 150.0}) EXPECT_NEAR(model.diameter_um(model.removed_px(d)), d, 0.05) << d;
  EXPECT_EQ(model.diameter_um(0.0), 0.0);
  EXPECT_LT(model.removed_px(10.0), model.removed_px(10.5));
  EXPECT_THROW(DropletSizeModel(two_cameras(), {30.0}), Error);
  EXPECT_THROW(DropletSizeModel(two_cameras(), {30.0, 0.0}), Error);
}

}  // namespace
}  // namespace tomorig::optics
