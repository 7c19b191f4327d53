#pragma once
// The point-spread half-width from edges (knife-edge technique, thesis Sect. 6.4): an image of
// a target with sharp straight edges (a chessboard or bar photomask) gives each edge's step
// response (edge spread function); its derivative is the line spread function, fitted with a
// Gaussian exp(-2 x^2 / chi^2) whose half-width equals the circular Gaussian PSF's (Eq. 6.1).
//
// Edges must run within +-30 degrees of the image's vertical and be slightly slanted (a few
// degrees), so that the rows sample the edge at every sub-pixel phase: the edge spread is then
// binned at a quarter pixel across the edge (the slanted-edge method) and the result includes
// the pixel's own integration, as a reconstruction sees it.
#include <vector>

#include "tomorig/core/image.h"

namespace tomorig::optics {

struct EdgeSpreadOptions {
  int half_width_px = 12;    // samples up to this distance either side of an edge
  double bin_px = 0.25;      // edge-spread bin across the edge
  double min_contrast = 0.2;  // (light - dark) / light of a row for its edges to count
  int min_rows = 20;         // rows an edge must cross to be measured
  // Rows dropped at both ends of each edge before it is measured: a chessboard's edges end at
  // corners, where the crossing edge would widen the spread (0: keep every row, for bars).
  int end_margin_rows = 0;
  // chi from the mean edge spread of all edges (each centred on its own line) instead of the
  // median of the edges' own fits: for flat-fielded images, whose edges share one level, and
  // short edges (a chessboard's), whose sub-pixel phases the pooled spread covers better.
  bool pool_edges = false;
};

struct EdgeMeasurement {
  double position_px = 0;  // edge column at the image's middle row
  double slope = 0;        // du / dv of the edge line
  double chi_px = 0;       // fitted LSF half-width, pixels
  double rms_residual = 0; // of the Gaussian fit, relative to its peak
  int rows = 0;
};

struct EdgePsf {
  std::vector<EdgeMeasurement> edges;
  double chi_px = 0;  // median over the edges, or the pooled spread's (pool_edges)
  double rms_residual = 0;  // the pooled fit's (pool_edges), relative to its peak
};

// Throws bad_input if the image has no measurable edge (names the image size and contrast).
EdgePsf measure_edge_psf(const Image& image, const EdgeSpreadOptions& options = {});

// The Gaussian fit on its own: samples (x, y) of a line spread function, returns the half-width
// chi of A exp(-2 (x - x0)^2 / chi^2) + c (least squares, Gauss-Newton from the moments).
// Throws bad_input for fewer than 5 samples or no peak.
double fit_line_spread_chi(const std::vector<double>& x, const std::vector<double>& y, double* rms_residual = nullptr);

}  // namespace tomorig::optics
