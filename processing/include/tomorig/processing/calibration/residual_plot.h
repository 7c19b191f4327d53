#pragma once
// Calibration residuals as a picture (issue 23): for one camera and one target plane, the
// detected points on the image and, from each, an arrow to where the stored model projects the
// point, magnified so that the largest arrow is clearly visible; the magnification, RMS and
// maximum are written on the picture. Systematic patterns (a swirl: a wrong distortion model;
// all arrows one way: a wrong plane z) show at a glance. An 8-bit grey image, for
// storage::write_png.
#include <span>
#include <string>

#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct ResidualPlot {
  Image image;
  double magnification = 1;  // arrow length on the picture / residual, both in image pixels
  double rms_px = 0;
  double max_px = 0;
};

// `points` are one plane's correspondences; `size` the camera's image size (the picture keeps its
// aspect, at most `max_side` pixels on its longer side). Throws bad_input for no points or an
// empty image size.
ResidualPlot residual_plot(const CameraModel& model, std::span<const PointCorrespondence> points, ImageSize size,
                           const std::string& title, int max_side = 1000);

}  // namespace tomorig::calibration
