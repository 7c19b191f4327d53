#pragma once
// The Levenberg-Marquardt fit of a projection to point correspondences that the pinhole-based
// models (pinhole, pinhole_distortion, refractive) share: residuals are the reprojection errors
// (thesis Eq. A.3) in normalised pixels, the Jacobian is a central difference. Internal.
#include <functional>
#include <span>

#include <Eigen/Dense>

#include "levenberg_marquardt.h"
#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration::detail {

// Fills pixels[i] with where the model of parameters q puts points[i].world, for every point.
// May throw tomorig::Error for parameters outside the model's domain (a camera beyond its
// window, an index below 1): such a step is then no candidate of the LM.
using ProjectPoints = std::function<void(const Eigen::VectorXd& q, std::span<Vec2d> pixels)>;

// Minimises sum |project(p)_i - points[i].pixel|^2 / image_scale^2 over p, from p (in, out).
LmResult fit_projection(std::span<const PointCorrespondence> points, double image_scale, const ProjectPoints& project,
                        Eigen::VectorXd& p, const LmSettings& settings);

}  // namespace tomorig::calibration::detail
