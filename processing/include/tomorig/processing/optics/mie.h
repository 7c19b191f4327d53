#pragma once
// Lorenz–Mie scattering by a homogeneous sphere (Bohren & Huffman 1983, Ch. 4; the BHMIE
// algorithm with Wiscombe's 1979 choice of the number of terms): efficiencies and the angular
// amplitudes S1, S2. The thesis used MiePlot for the droplet transmission (Sect. 6.1); tomorig
// computes the series itself.
//
//   optics::MieSeries mie(x, {1.333, 1e-9});     // size parameter x = pi d / lambda (in the medium)
//   optics::MieEfficiencies q = mie.efficiencies();
//   optics::MieAmplitudes s = mie.amplitudes(0.01);  // S1, S2 at 10 mrad
//
// Conventions: m = n + i k is the index of the sphere relative to the medium, k >= 0 absorbing
// (Bohren & Huffman; Wiscombe writes n - i k). The logarithmic derivative D_n(m x) comes from
// downward recurrence, stable for any m; psi_n and chi_n of the real x from upward recurrence,
// stable up to the last term used.
#include <complex>
#include <vector>

namespace tomorig::optics {

struct MieEfficiencies {
  double q_ext = 0;   // extinction efficiency, C_ext / (pi a^2)
  double q_sca = 0;   // scattering efficiency
  double q_back = 0;  // backscattering efficiency (radar definition, B&H 4.82)
  double g = 0;       // asymmetry parameter <cos theta>
  double q_abs() const { return q_ext - q_sca; }
};

struct MieAmplitudes {
  std::complex<double> s1;  // perpendicular polarisation
  std::complex<double> s2;  // parallel polarisation
  // (|S1|^2 + |S2|^2) / 2: the unpolarised scattered intensity (B&H S11).
  double s11() const { return 0.5 * (std::norm(s1) + std::norm(s2)); }
};

class MieSeries {
 public:
  // Throws tomorig::Error (bad_input) for x <= 0, x > 1e5, n <= 0 or k < 0 (or non-finite).
  MieSeries(double size_parameter, std::complex<double> relative_index);

  double size_parameter() const { return x_; }
  int terms() const { return static_cast<int>(a_.size()); }
  const MieEfficiencies& efficiencies() const { return q_; }
  // S1, S2 at scattering angle theta (radians, 0 = forward).
  MieAmplitudes amplitudes(double theta) const;
  // The unpolarised intensity integrated over the forward cone 0..theta_max (radians),
  //   int_0^theta_max (|S1|^2 + |S2|^2) sin(theta) d theta,
  // by Simpson's rule on steps fine enough for the lobes of this x (about 12 per lobe).
  // Divided by x^2 Q_sca it is the fraction of the scattered power inside the cone.
  double forward_cone_integral(double theta_max) const;

 private:
  double x_;
  std::vector<std::complex<double>> a_, b_;
  MieEfficiencies q_;
};

}  // namespace tomorig::optics
