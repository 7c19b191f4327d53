#pragma once
// Sub-voxel location of a correlation peak along one axis from the peak value and its two
// neighbours: the 3-point Gaussian estimator, with fallbacks where it is undefined.
namespace tomorig::piv {

enum class PeakFitMethod { gaussian, parabolic, centroid, none };

struct PeakFit1d {
  double offset = 0.0;  // sub-voxel offset from the integer peak, in (-1, 1)
  PeakFitMethod method = PeakFitMethod::none;
};

// `has_left` / `has_right` are false where the peak sits at the edge of the correlation plane.
// Gaussian if all three values are > 0; parabolic if one is <= 0; at an edge, the centroid of the
// peak and its one neighbour (clamped to +-0.5).
PeakFit1d fit_peak_1d(double left, double centre, double right, bool has_left = true, bool has_right = true);

}  // namespace tomorig::piv
