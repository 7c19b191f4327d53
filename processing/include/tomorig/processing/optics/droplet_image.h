#pragma once
// The droplet imaging model of thesis Sect. 6.1 (Blaisot & Yon 2005): a droplet's shadow is a
// slightly transmitting disc (transmission tau, Eq. 6.2) convolved with a Gaussian point-spread
// function s(r) = s0 exp(-2 r^2 / chi^2) of half-width chi (Eq. 6.1).
//
// Lengths: d and chi are given in the same space, here object space in um (the thesis measures
// chi in back-projected voxel space, Sect. 6.4); image-space values differ by the magnification
// M on both and the model only uses their ratio.
namespace tomorig::optics {

// Normalised intensity i(r) of the shadow of a droplet of diameter d at distance r from its
// centre (Eq. 6.4), 1 = bright field:
//   i(r~) = 1 - 2 (1 - tau) exp(-r~^2) int_0^a~ exp(-rho^2) I0(2 r~ rho) rho d rho,
//   r~ = sqrt2 r / chi, a~ = sqrt2 (d / 2) / chi.
// (The thesis prints Eq. 6.4 without the factor rho in the integrand; with it the profile is
// the 2-D convolution of disc and Gaussian and its centre value is Eq. 6.6.)
// Throws bad_input for d < 0, chi <= 0, tau outside [0, 1] or r < 0.
double shadow_profile(double r, double d, double chi, double tau);

// The minimum, at the centre (Eq. 6.6): 1 - (1 - tau) (1 - exp(-a~^2)).
double minimum_intensity(double d, double chi, double tau);

// The object-side numerical aperture of a lens at f-number f# and magnification M (Eq. 6.5,
// small apertures, entrance pupil at the object-side principal plane): 1 / (2 f# (1 + 1/M)).
// Throws bad_input for f# <= 0 or M <= 0.
double object_numerical_aperture(double f_number, double magnification);

}  // namespace tomorig::optics
