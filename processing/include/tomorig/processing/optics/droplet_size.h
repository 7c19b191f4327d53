#pragma once
// A droplet's diameter from the light its shadow removes (the thesis's intensity as size
// indicator, Sect. 7.4, made quantitative with the imaging model of Sect. 6.1). Integrated over
// the image, the blurred shadow of Eq. 6.4 removes exactly (1 - tau) pi d^2 / 4 of the
// flat-fielded bright field whatever the PSF's half-width chi, so the depth (and focus) drops
// out; an additive reconstruction (MENT) keeps that light in the droplet's blob, each voxel's
// weights summing to one per camera. Inverting it gives the blob's diameter and size class.
//
//   DropletSizeModel m(setup, {28.7, 27.4, 28.0, 28.6});   // object pixel of each camera, um
//   double d = m.diameter_um(blob.integrated / 1000.0);     // shadow presets: bright field 1000
#include <vector>

#include "tomorig/processing/optics/visibility.h"

namespace tomorig::optics {

class DropletSizeModel {
 public:
  // setup: each camera's aperture (f#, M) and the liquid and LED; object_pixel_um: each
  // camera's pixel in the object plane (pitch / M), in the setup's camera order. Throws
  // bad_input for a count mismatch or a pixel <= 0.
  DropletSizeModel(const VisibilitySetup& setup, const std::vector<double>& object_pixel_um);

  // The light a droplet of d_um removes from a flat-fielded image (full depth = 1 per pixel),
  // in pixels, averaged over the cameras.
  double removed_px(double d_um) const;
  // The inverse: the diameter whose shadow removes `removed_px`; 0 for nothing removed, the
  // setup's d_max beyond its range.
  double diameter_um(double removed_px) const;

 private:
  std::vector<double> d_, removed_;  // ascending in both
};

}  // namespace tomorig::optics
