#pragma once
// The point-spread model of one camera (thesis Eq. 3.8): an axis-aligned elliptical Gaussian
// whose widths may vary with depth. The thesis used one constant sigma for FMART and names the
// depth-varying PSF as the missing piece (Sect. 5.6, 8.2); here sigma is given at a list of
// world z values and interpolated linearly between them (held constant beyond the ends).
//
//   PsfModel psf = PsfModel::constant(0.75);                       // circular, any depth
//   PsfModel psf{{{-1.5, 1.0, 1.0}, {0.0, 0.75, 0.75}, {1.5, 1.0, 1.2}}};  // defocus with depth
#include <string>
#include <vector>

namespace tomorig::recon {

struct PsfSample {
  double z_mm = 0.0;        // world z of this sample
  double sigma_u_px = 0.75;  // Gaussian sigma along image columns (u), pixels
  double sigma_v_px = 0.75;  // Gaussian sigma along image rows (v), pixels
};

struct PsfModel {
  std::vector<PsfSample> samples;  // ascending z_mm; one sample means a constant PSF

  static PsfModel constant(double sigma_px) { return {{{0.0, sigma_px, sigma_px}}}; }

  // sigma at world depth z: linear interpolation between samples, constant beyond the ends.
  PsfSample at(double z_mm) const;
  // The largest sigma (u or v) over all samples: sets the patch size p = ceil(4 sigma).
  double max_sigma() const;
  // Throws tomorig::Error (bad_input) naming `what` (e.g. "camera 2 PSF") if there are no
  // samples, z is not strictly ascending, or a sigma is not in (0, 10] px.
  void validate(const std::string& what) const;
};

}  // namespace tomorig::recon
