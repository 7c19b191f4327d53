#pragma once
// The point-spread model of one camera (thesis Eq. 3.8): an elliptical Gaussian, rotated by an
// angle (the b term of Eq. 3.8, e.g. astigmatism), whose widths and angle may vary with depth. The thesis used one constant sigma for FMART and names the
// depth-varying PSF as the missing piece (Sect. 5.6, 8.2); here sigma is given at a list of
// world z values and interpolated linearly between them (held constant beyond the ends).
//
//   PsfModel psf = PsfModel::constant(0.75);                       // circular, any depth
//   PsfModel psf{{{-1.5, 1.0, 1.0}, {0.0, 0.75, 0.75}, {1.5, 1.0, 1.2}}};  // defocus with depth
//   PsfModel psf{{{0.0, 0.9, 0.5, 0.6}}};   // ellipse 0.9 x 0.5 px, major axis 0.6 rad from u
#include <string>
#include <vector>

namespace tomorig::recon {

// The weight sigma every camera gets when the input names no PSF (ReconstructionInput::psf
// empty), and the default of every --sigma-px: it reproduces sigma = 0.75 px particle images
// from blobs as wide as the thesis's truth (reconstructor.h, docs/reconstruction.md).
inline constexpr double kDefaultPsfSigmaPx = 0.5;

struct PsfSample {
  double z_mm = 0.0;        // world z of this sample
  double sigma_u_px = 0.75;  // Gaussian sigma along the ellipse's first axis (image u when angle 0), pixels
  double sigma_v_px = 0.75;  // Gaussian sigma along its second axis (image v when angle 0), pixels
  // Angle of the first axis from the image u axis towards v, radians. 0: axis-aligned, and the
  // weights are separable (cheaper); otherwise a 2-D weight table per depth level is used.
  double angle_rad = 0.0;
};

struct PsfModel {
  std::vector<PsfSample> samples;  // ascending z_mm; one sample means a constant PSF

  static PsfModel constant(double sigma_px) { return {{{0.0, sigma_px, sigma_px}}}; }

  // sigma and angle at world depth z: linear interpolation between samples, constant beyond
  // the ends.
  PsfSample at(double z_mm) const;
  // The largest sigma (u or v) over all samples: sets the patch size p = ceil(4 sigma).
  double max_sigma() const;
  // Throws tomorig::Error (bad_input) naming `what` (e.g. "camera 2 PSF") if there are no
  // samples, z is not strictly ascending, a sigma is not in (0, 10] px or an angle is not in
  // [-pi, pi].
  void validate(const std::string& what) const;
};

}  // namespace tomorig::recon
