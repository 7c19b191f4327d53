#pragma once
// The droplet transmission tau (thesis Sect. 6.1, Fig. 6.3-6.4): the fraction of the light a
// droplet scatters that the lens aperture still collects, i.e. the phase function (the
// scattered intensity normalised over all directions) integrated over the object-side cone of
// the aperture, NA from Eq. 6.5. Computed with the Mie series for unpolarised light and
// averaged over the LED spectrum, weighting each wavelength by its power and the droplet's
// scattering cross-section (so the average is of scattered power, as MiePlot's polychromatic
// phase function).
//
//   optics::TransmissionModel model(optics::Liquid::kerosene(), optics::LedSpectrum{});
//   double tau = model.transmission(20.0, optics::object_numerical_aperture(22, 0.9));
#include <complex>
#include <string>
#include <vector>

namespace tomorig::optics {

// A liquid's refractive index in air: Cauchy dispersion n(lambda) = n_D + B (1/lambda^2 -
// 1/589.3^2) (lambda in nm) and a constant absorption index k.
struct Liquid {
  std::string name;
  double n_d = 1.333;          // at the sodium D line, 589.3 nm
  double cauchy_b_nm2 = 3130;  // dispersion
  double k = 1e-9;             // imaginary part (absorbing >= 0)

  std::complex<double> index(double wavelength_nm) const;
  // Water at 20 C: n_D = 1.3330, Abbe number 55.7 (B = 3130 nm^2), k ~ 1e-9 in the green.
  static Liquid water();
  // Kerosene (Jet A-1) at 20 C: n_D = 1.44, Abbe number ~57 of alkanes (B = 4000 nm^2), and
  // the thesis's absorption index 5e-7 (Sect. 6.1, [127]).
  static Liquid kerosene();
  // "water" or "kerosene"; throws bad_input naming the choices otherwise.
  static Liquid named(const std::string& name);
};

// A Gaussian emission spectrum sampled at `samples` wavelengths over peak +- 1.5 FWHM (weights
// the Gaussian's). fwhm_nm = 0: monochromatic at peak_nm. Default: the thesis's SST-90 green
// LED at 270 A (Sect. 7.3: peak 514 nm, 37 nm FWHM).
struct LedSpectrum {
  double peak_nm = 514.0;
  double fwhm_nm = 37.0;
  int samples = 9;

  void validate() const;  // bad_input naming the field
  struct Line {
    double wavelength_nm;
    double weight;  // sums to 1
  };
  std::vector<Line> lines() const;
};

class TransmissionModel {
 public:
  // Throws bad_input for a bad spectrum or a liquid with n <= 0 or k < 0.
  TransmissionModel(Liquid liquid, LedSpectrum spectrum);

  const Liquid& liquid() const { return liquid_; }
  const LedSpectrum& spectrum() const { return spectrum_; }

  // tau for a droplet of diameter d_um (> 0, <= 2000 um) seen through an object-side
  // numerical aperture `na` (the half-angle's sine, in (0, 1)). Throws bad_input otherwise.
  double transmission(double d_um, double na) const;

 private:
  Liquid liquid_;
  LedSpectrum spectrum_;
  std::vector<LedSpectrum::Line> lines_;
};

}  // namespace tomorig::optics
