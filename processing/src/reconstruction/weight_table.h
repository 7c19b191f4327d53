#pragma once
// Gaussian weights w_ij of Eq. 3.8/3.10 from a lookup table (thesis Sect. 3.1.3).
//
// The PSF is an axis-aligned elliptical Gaussian, so a weight is the product of a u factor and
// a v factor; each factor is the Gaussian integrated over the pixel's width (the sensor
// integrates light over its pixels, as the simulator does). A voxel imaged at u spreads over
// the p pixels start .. start + p - 1 with start = floor(u - (p - 1) / 2 + 1/2) (the patch is
// centred on the voxel's image); the sub-pixel phase of u within that patch is quantised to
// `steps` per pixel and selects a row of p weights. Sigma may differ per z-slice: each distinct
// sigma (to 1e-3 px) is a "level" with its own `steps` rows.
#include <cmath>
#include <cstdint>
#include <vector>

#include "tomorig/processing/reconstruction/psf_model.h"

namespace tomorig::recon::detail {

class AxisWeights {
 public:
  AxisWeights() = default;
  // sigma_of_slice[k]: sigma of slice k, px.
  AxisWeights(const std::vector<double>& sigma_of_slice, int patch, int steps);

  // Patch start and LUT row of a voxel at image coordinate `pos` in slice k.
  void locate(float pos, int k, int& start, std::uint16_t& row) const {
    // Nearest step and floor division by truncation of positive numbers: positions are
    // > -kShift px, and this avoids the libm calls of lround/floor in a per-voxel loop.
    constexpr long kShift = 1L << 20;
    const long t = static_cast<long>((static_cast<double>(pos) - 0.5 * (patch_ - 1) + 0.5 + kShift) * steps_ + 0.5);
    const long s = t / steps_;
    start = static_cast<int>(s - kShift);
    row = static_cast<std::uint16_t>(slice_level_[k] * steps_ + (t - s * steps_));
  }
  const float* table() const { return weights_.data(); }
  int patch() const { return patch_; }
  int levels() const { return levels_; }

 private:
  int patch_ = 0, steps_ = 0, levels_ = 0;
  std::vector<float> weights_;          // (levels * steps) rows of patch weights
  std::vector<std::uint16_t> slice_level_;
};

// Weights of a rotated elliptical PSF (Eq. 3.8 with b != 0), which is not separable: per
// level (distinct sigma_u, sigma_v, angle) and sub-pixel phase pair (qu, qv) a full p x p block
// of the Gaussian integrated over each pixel (8 x 8 sub-samples). The phases are those of an
// AxisWeights with a single level (its row is the phase), so the patch placement is the same
// as in the separable case.
class PatchWeights {
 public:
  PatchWeights() = default;
  PatchWeights(const std::vector<PsfSample>& psf_of_slice, int patch, int steps, int threads);

  std::uint32_t row(int k, int qu, int qv) const {
    return (static_cast<std::uint32_t>(slice_level_[k]) * steps_ + static_cast<std::uint32_t>(qv)) * steps_ +
           static_cast<std::uint32_t>(qu);
  }
  const float* table() const { return weights_.data(); }  // row r: p * p weights, v-major
  int levels() const { return levels_; }

 private:
  int patch_ = 0, steps_ = 0, levels_ = 0;
  std::vector<float> weights_;
  std::vector<std::uint32_t> slice_level_;
};

// Whether a PSF needs PatchWeights: a rotation angle away from 0 (and from +-pi) at any depth.
bool is_rotated(const PsfSample& psf);

// Weight of the pixel whose centre lies at (du, dv) from the image position, for a rotated
// elliptical Gaussian: integrated over the pixel by n x n midpoint sub-samples.
double pixel_integrated_gaussian_2d(double du, double dv, const PsfSample& psf, int n = 8);

// Weight of the pixel at signed distance d (pixel centre minus image position) for sigma.
double pixel_integrated_gaussian(double d, double sigma);

}  // namespace tomorig::recon::detail
