#include "tomorig/processing/optics/transmission.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/mie.h"

namespace tomorig::optics {

std::complex<double> Liquid::index(double wavelength_nm) const {
  constexpr double kSodiumD = 589.3;
  const double n = n_d + cauchy_b_nm2 * (1.0 / (wavelength_nm * wavelength_nm) - 1.0 / (kSodiumD * kSodiumD));
  return {n, k};
}

Liquid Liquid::water() { return {"water", 1.3330, 3130.0, 1e-9}; }
Liquid Liquid::kerosene() { return {"kerosene", 1.44, 4000.0, 5e-7}; }

Liquid Liquid::named(const std::string& name) {
  if (name == "water") return water();
  if (name == "kerosene") return kerosene();
  throw bad_input(fmt::format("liquid '{}' is unknown: use water or kerosene", name));
}

void LedSpectrum::validate() const {
  if (!(peak_nm >= 200.0 && peak_nm <= 2000.0))
    throw bad_input(fmt::format("LED spectrum: peak_nm = {} is out of range [200, 2000]", peak_nm));
  if (!(fwhm_nm >= 0.0 && fwhm_nm <= 0.5 * peak_nm))
    throw bad_input(fmt::format("LED spectrum: fwhm_nm = {} must be in [0, peak_nm / 2]", fwhm_nm));
  if (samples < 1 || samples > 101)
    throw bad_input(fmt::format("LED spectrum: samples = {} must be in [1, 101]", samples));
}

std::vector<LedSpectrum::Line> LedSpectrum::lines() const {
  validate();
  if (fwhm_nm == 0.0 || samples == 1) return {{peak_nm, 1.0}};
  const double sigma = fwhm_nm / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  std::vector<Line> out;
  double total = 0.0;
  for (int i = 0; i < samples; ++i) {
    const double offset = -1.5 * fwhm_nm + 3.0 * fwhm_nm * i / (samples - 1);
    const double w = std::exp(-0.5 * offset * offset / (sigma * sigma));
    out.push_back({peak_nm + offset, w});
    total += w;
  }
  for (Line& l : out) l.weight /= total;
  return out;
}

TransmissionModel::TransmissionModel(Liquid liquid, LedSpectrum spectrum)
    : liquid_(std::move(liquid)), spectrum_(spectrum), lines_(spectrum_.lines()) {
  if (!(liquid_.n_d > 0.0) || !(liquid_.k >= 0.0) || !std::isfinite(liquid_.cauchy_b_nm2))
    throw bad_input(fmt::format("liquid '{}': n_D = {} must be > 0 and k = {} >= 0", liquid_.name, liquid_.n_d,
                                liquid_.k));
}

double TransmissionModel::transmission(double d_um, double na) const {
  if (!(d_um > 0.0 && d_um <= 2000.0))
    throw bad_input(fmt::format("droplet diameter {} um is out of range (0, 2000]", d_um));
  if (!(na > 0.0 && na < 1.0)) throw bad_input(fmt::format("numerical aperture {} must be in (0, 1)", na));
  const double cone = std::asin(na);
  double collected = 0.0, scattered = 0.0;
  for (const LedSpectrum::Line& line : lines_) {
    const double lambda_um = line.wavelength_nm * 1e-3;
    const double x = M_PI * d_um / lambda_um;
    const MieSeries mie(x, liquid_.index(line.wavelength_nm));
    // Per unit incident irradiance: C_sca = lambda^2 / (2 pi) * int (|S1|^2 + |S2|^2)/2 sin dtheta,
    // so both sums carry lambda^2; the cone part is the same integral up to the aperture.
    const double k2 = lambda_um * lambda_um / (4.0 * M_PI * M_PI);
    collected += line.weight * k2 * 2.0 * M_PI * 0.5 * mie.forward_cone_integral(cone);
    scattered += line.weight * mie.efficiencies().q_sca * M_PI * 0.25 * d_um * d_um;
  }
  return scattered > 0.0 ? std::min(1.0, collected / scattered) : 0.0;
}

}  // namespace tomorig::optics
