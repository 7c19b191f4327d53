// The droplet imaging model of thesis Sect. 6.1: Eq. 6.4 against its own limits and against
// the 2-D convolution it stands for, Eq. 6.5 and 6.6, and the transmission against the two
// limits scattering theory gives in closed form (Rayleigh and Fraunhofer).
#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/processing/optics/mie.h"
#include "tomorig/processing/optics/transmission.h"

namespace tomorig::optics {
namespace {

TEST(DropletImage, CentreOfTheProfileIsEquation66) {
  for (double d : {2.0, 10.0, 30.0, 100.0})
    for (double chi : {10.0, 40.0})
      for (double tau : {0.0, 0.1, 0.6})
        EXPECT_NEAR(shadow_profile(0.0, d, chi, tau), minimum_intensity(d, chi, tau), 1e-7)
            << "d " << d << " chi " << chi << " tau " << tau;
  // 1 - exp(-a~^2) with a~ = sqrt2 * 5 / 10: d = 10, chi = 10, opaque.
  EXPECT_NEAR(minimum_intensity(10.0, 10.0, 0.0), std::exp(-0.5), 1e-12);
}

TEST(DropletImage, ProfileRemovesExactlyTheDiscsShadow) {
  // The PSF is normalised: the depletion integrated over the plane is (1 - tau) pi a^2 for any
  // blur. Integrate Eq. 6.4 numerically out to where it is 1.
  const double d = 24.0, chi = 30.0, tau = 0.2;
  const double step = 0.25;
  double depletion = 0.0;
  for (double r = step / 2; r < 200.0; r += step) depletion += (1.0 - shadow_profile(r, d, chi, tau)) * 2 * M_PI * r * step;
  EXPECT_NEAR(depletion / ((1 - tau) * M_PI * d * d / 4), 1.0, 1e-3);
}

TEST(DropletImage, LargeDropletIsAFlatTopAtTauWithHalfDepthEdge) {
  // Sect. 6.1: a droplet five times the PSF half-width gives a flat top at i = tau.
  const double chi = 10.0, d = 200.0, tau = 0.3;
  EXPECT_NEAR(shadow_profile(0.0, d, chi, tau), tau, 1e-6);
  EXPECT_NEAR(shadow_profile(50.0, d, chi, tau), tau, 1e-6);
  EXPECT_NEAR(shadow_profile(100.0, d, chi, tau), 1.0 - 0.5 * (1 - tau), 0.01);  // the edge
  EXPECT_NEAR(shadow_profile(140.0, d, chi, tau), 1.0, 1e-6);
  // Small droplets in a wide PSF: a shallow dip.
  EXPECT_GT(minimum_intensity(5.0, 40.0, 0.05), 0.98);
}

TEST(DropletImage, NumericalApertureIsEquation65) {
  EXPECT_NEAR(object_numerical_aperture(12, 1.0), 1.0 / 48.0, 1e-15);
  EXPECT_NEAR(object_numerical_aperture(22, 0.9), 1.0 / (44.0 * (1.0 + 1.0 / 0.9)), 1e-15);
  EXPECT_THROW(object_numerical_aperture(0, 1), Error);
  EXPECT_THROW(object_numerical_aperture(22, -1), Error);
}

TEST(DropletImage, RefusesBadArguments) {
  EXPECT_THROW(shadow_profile(-1, 10, 10, 0.1), Error);
  EXPECT_THROW(shadow_profile(0, 10, 0, 0.1), Error);
  EXPECT_THROW(minimum_intensity(10, 10, 1.5), Error);
  EXPECT_THROW(minimum_intensity(-1, 10, 0.5), Error);
}

TEST(Transmission, RayleighLimitFollowsOnePlusCosSquared) {
  // x << 1 (here 0.03: corrections of order x^2 ~ 1e-3): the unpolarised intensity goes as (1 + cos^2 theta); the fraction inside a cone of
  // half-angle t is [(1 - cos t) + (1 - cos^3 t) / 3] / (8 / 3).
  const TransmissionModel model(Liquid::water(), LedSpectrum{532.0, 0.0, 1});
  for (double na : {0.2, 0.5, 0.9}) {
    const double c = std::cos(std::asin(na));
    const double expected = ((1 - c) + (1 - c * c * c) / 3.0) / (8.0 / 3.0);
    EXPECT_NEAR(model.transmission(0.005, na), expected, 1e-3 * expected) << "NA " << na;
  }
}

TEST(Transmission, LargeAbsorbingSphereScattersLikeAnAiryDisc) {
  // Fraunhofer limit: a large black disc diffracts pi a^2, with the Airy encircled energy
  // 1 - J0^2(x t) - J1^2(x t) inside the cone of half-angle t; int_0^t (|S1|^2 + |S2|^2) sin /
  // x^2 = C / (pi a^2) inside the cone. m = 1 + 0.3i: absorbed within a fraction of a wavelength,
  // reflecting ~2 %, mostly outside the cone.
  const double x = 1000.0;
  const MieSeries mie(x, {1.0, 0.3});
  for (double xt : {3.8317, 7.0156, 10.1735}) {  // the first three dark rings: 1 - J0^2
    const double airy = 1.0 - std::pow(std::cyl_bessel_j(0.0, xt), 2) - std::pow(std::cyl_bessel_j(1.0, xt), 2);
    EXPECT_NEAR(mie.forward_cone_integral(xt / x) / (x * x), airy, 0.01) << "x t = " << xt;
  }
}

TEST(Transmission, GrowsWithDiameterAndApertureForKeroseneInLedLight) {
  // Fig. 6.4: at a fixed aperture, bigger droplets put more of their scattered light into it.
  const TransmissionModel model(Liquid::kerosene(), LedSpectrum{});
  const double na = object_numerical_aperture(22, 1.0);
  const double t10 = model.transmission(10.0, na), t50 = model.transmission(50.0, na);
  EXPECT_GT(t10, 0.0);
  EXPECT_LT(t10, 0.15);
  EXPECT_GT(t50, t10);
  EXPECT_LT(t50, 0.6);  // diffraction is half the scattering, and not all of it enters
  EXPECT_GT(model.transmission(50.0, object_numerical_aperture(8, 1.0)), t50);
  EXPECT_THROW(model.transmission(0.0, na), Error);
  EXPECT_THROW(model.transmission(10.0, 1.5), Error);
  EXPECT_THROW(Liquid::named("honey"), Error);
  EXPECT_THROW((TransmissionModel(Liquid::water(), LedSpectrum{514, -1, 9})), Error);
}

}  // namespace
}  // namespace tomorig::optics
