// The 3-point Gaussian estimator and its fallbacks, against values sampled from known curves.
#include <cmath>

#include <gtest/gtest.h>

#include "tomorig/processing/correlation/peak_fit.h"

namespace {

using namespace tomorig::piv;

double gauss(double x, double centre) { return std::exp(-(x - centre) * (x - centre) / 2.0); }

TEST(PeakFit, GaussianRecoversTheCentreOfAGaussian) {
  for (double centre : {-0.4, -0.1, 0.0, 0.25, 0.45}) {
    const PeakFit1d fit = fit_peak_1d(gauss(-1, centre), gauss(0, centre), gauss(1, centre));
    EXPECT_EQ(fit.method, PeakFitMethod::gaussian);
    EXPECT_NEAR(fit.offset, centre, 1e-9);
  }
}

TEST(PeakFit, NonPositiveNeighbourFallsBackToParabola) {
  // A parabola through (-1, -0.2), (0, 1), (1, 0.6): vertex at (L - R) / (2L - 4C + 2R).
  const PeakFit1d fit = fit_peak_1d(-0.2, 1.0, 0.6);
  EXPECT_EQ(fit.method, PeakFitMethod::parabolic);
  EXPECT_NEAR(fit.offset, (-0.2 - 0.6) / (2 * -0.2 - 4 * 1.0 + 2 * 0.6), 1e-12);
}

TEST(PeakFit, PeakAtTheEdgeUsesTheCentroidOfTheRemainingNeighbour) {
  const PeakFit1d right_edge = fit_peak_1d(0.5, 1.0, 123.0, true, false);
  EXPECT_EQ(right_edge.method, PeakFitMethod::centroid);
  EXPECT_NEAR(right_edge.offset, -0.5 / 1.5, 1e-12);
  const PeakFit1d left_edge = fit_peak_1d(123.0, 1.0, 0.25, false, true);
  EXPECT_EQ(left_edge.method, PeakFitMethod::centroid);
  EXPECT_NEAR(left_edge.offset, 0.25 / 1.25, 1e-12);
}

}  // namespace
