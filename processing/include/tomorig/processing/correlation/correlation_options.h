#pragma once
// Options of the 3-D cross-correlation (thesis Sect. 2.5, 5.4.3, 7.5): a list of passes run
// coarse to fine, each feeding its validated, smoothed field to the next as predictor.
#include <functional>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/volume.h"

namespace tomorig::piv {

enum class WindowWeighting { top_hat, gaussian, hann };
enum class Interpolation { trilinear, cubic_bspline };
// How a pass with a predictor (the integer-offset pass and the deformation passes) correlates
// its windows: `automatic` chooses sparse direct correlation (lags -1..1 around the predictor,
// the FFT for a window whose peak lies beyond them) when the volumes are sparse enough for it
// to cost less than the FFTs, else FFT; the first pass, without a predictor, always uses the FFT.
enum class CorrelationMethod { automatic, fft, direct };

struct WindowSize {
  int x = 32, y = 32, z = 32;  // voxels of the full-resolution grid
};

struct CorrelationPass {
  WindowSize window;
  double overlap = 0.5;        // fraction of a window shared with its neighbour, [0, 0.875]
  int downsample = 1;          // correlate volumes binned by summing N^3 voxels (1, 2 or 4)
  bool deformation = false;    // deform both volumes by -/+ half the predictor (Eq. 2.17)
  Interpolation interpolation = Interpolation::cubic_bspline;
  CorrelationMethod method = CorrelationMethod::automatic;
};

// The normalised median test of Westerweel & Scarano (2005) on the 3x3x3 neighbourhood.
struct MedianTestOptions {
  bool enabled = true;
  double epsilon = 0.1;     // voxel: expected noise level of the displacement
  double threshold = 2.0;   // normalised residual above which a component fails
};

struct CorrelationOptions {
  std::vector<CorrelationPass> passes;
  WindowWeighting weighting = WindowWeighting::top_hat;
  // Standard deviation of the Gaussian weighting, as a fraction of the window edge along each
  // axis, (0, 2]. Narrow (0.25) resolves gradients best on clean volumes; wide (0.5) averages
  // more particles against the ghosts of reconstructed ones (docs/correlation.md).
  double gaussian_sigma = 0.25;
  double min_peak = 0.1;              // minimum correlation coefficient (Sect. 7.5); 0 disables
  double max_displacement = 0.0;      // voxel, largest accepted magnitude; 0 disables
  MedianTestOptions median_test;
  bool smooth_predictor = true;       // 3x3x3 Gaussian of the predictor between passes (Sect. 2.5)
  // Illumination mask: fraction (0..1) of the peak light-sheet intensity at a world point (mm);
  // nodes below `min_illumination` are flagged invalid. Empty: no mask.
  std::function<double(const Vec3d& world_mm)> illumination;
  double min_illumination = 0.4;      // the "light sheet intensity > 40 %" of Table 5.5
  int threads = 0;                    // OpenMP threads; 0: the OpenMP default

  // Throws tomorig::Error (bad_input) naming the field that is out of range, including windows
  // larger than `grid`.
  void validate(const VoxelGrid& grid) const;

  // The thesis's scheme: one pass at twice the final window on volumes binned 2x (50 %
  // overlap), one at the final window with integer offset (at most 50 % overlap when
  // deformation passes follow, else `overlap`), then `deformation_passes` deformation passes
  // at `overlap`.
  static CorrelationOptions multigrid(WindowSize final_window, double overlap, int deformation_passes,
                                      Interpolation interpolation = Interpolation::cubic_bspline);
};

}  // namespace tomorig::piv
