#pragma once
// The particle image model behind the quick-look's d_tau and ppp (docs/quicklook.md):
//
// A particle image is a Gaussian of standard deviation sigma (d_tau = 4 sigma, its e^-2
// diameter, thesis Fig. 2.3 / Table 3.1) integrated over square pixels. For particles at random
// positions the image's autocovariance is the particle image's own autocorrelation times the
// density (Campbell's theorem), whatever the density; along x it is
//   h(lag) = integral over t in [-1, 1] of (1 - |t|) phi_s(lag - t) dt,  s = sqrt(2) sigma,
// the autocorrelation of the Gaussian (phi_s) convolved with that of the pixel box (the
// triangle). White noise adds to lag 0 only, so sigma comes from the ratio of lags 1 and 2.
//
// Particle image density from the same sums: the mean excess intensity is rho E[a] and the
// lag-(1, 0) autocovariance rho E[a^2] h(1) h(0) (a: a particle image's integrated counts), so
//   excess^2 h(0) h(1) / c(1, 0) = rho E[a]^2 / E[a^2],
// exact at any density for equally bright images: overlapping images do not bias it, unlike a
// count of local maxima. Unequal brightness makes it a lower bound (E[a]^2 <= E[a^2]), as
// overlaps make the count of local maxima one; statistics.cpp keeps the larger of the two.
namespace tomorig::quicklook::detail {

// h(lag) above for a particle image of standard deviation `sigma_px`.
double pixel_autocorrelation(double lag, double sigma_px);

// sigma (px) whose h(1) / h(2) equals `ratio`; NaN outside the model's range (sigma in
// [0.2, 8] px).
double sigma_from_lag_ratio(double ratio);

// rho E[a]^2 / E[a^2] from the mean excess intensity and the mean of the lag-1
// autocovariances along x and y; NaN unless all are positive and sigma is finite.
double density_from_autocovariance(double excess, double lag1_covariance, double sigma_px);

}  // namespace tomorig::quicklook::detail
