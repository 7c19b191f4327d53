// Correcting the cameras from their sub-volume disparities: choosing the gauge, smoothing
// the corrections into a field, and refitting each camera's model to it.
#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/core.h>

#include "self_calibration_internal.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/refractive_camera.h"

namespace tomorig::calibration::selfcal {
namespace {

constexpr int kGaugeIterations = 50;
constexpr double kStepMm = 0.01;  // central differences of the projection
constexpr int kLatticeXY = 13, kLatticeZ = 5;

// d(pixel) / d(world) at `world`, 2 x 3.
Eigen::Matrix<double, 2, 3> projection_jacobian(const CameraModel& model, const Vec3d& world) {
  Eigen::Matrix<double, 2, 3> j;
  for (int axis = 0; axis < 3; ++axis) {
    Vec3d step;
    (axis == 0 ? step.x : axis == 1 ? step.y : step.z) = kStepMm;
    const Vec2d plus = model.project(world + step), minus = model.project(world - step);
    j(0, axis) = (plus.x - minus.x) / (2 * kStepMm);
    j(1, axis) = (plus.y - minus.y) / (2 * kStepMm);
  }
  return j;
}

}  // namespace

DisparityMaps gauge_corrections(const ModelList& initial, const ModelList& models, const DisparityMaps& maps,
                                bool sparse_gauge) {
  DisparityMaps out = maps;
  if (!sparse_gauge) return out;
  const std::size_t cameras = models.size(), subvolumes = maps.front().size();
  std::vector<Eigen::Matrix<double, 2, 3>> jac(cameras);
  std::vector<Eigen::Vector2d> d(cameras), applied(cameras);
  for (std::size_t s = 0; s < subvolumes; ++s) {
    std::vector<std::size_t> valid;
    Vec3d where;
    for (std::size_t c = 0; c < cameras; ++c)
      if (maps[c][s].valid) {
        valid.push_back(c);
        where = where + maps[c][s].centroid;
      }
    if (valid.size() < 2) continue;
    where = where * (1.0 / static_cast<double>(valid.size()));
    for (const std::size_t c : valid) {
      jac[c] = projection_jacobian(*models[c], where);
      d[c] = {maps[c][s].disparity.x, maps[c][s].disparity.y};
      const Vec2d was = initial[c]->project(where), now = models[c]->project(where);
      applied[c] = {was.x - now.x, was.y - now.y};
    }
    // Weiszfeld-style reweighting: minimise sum_c |applied_c + d_c + J_c shift| over the world
    // shift: the sparsest total correction relative to the initial models. Anchoring to the
    // initial models (not only this pass's disparities) keeps a first, ghost-ridden estimate
    // from leaving a world-frame error that later passes cannot see.
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (int it = 0; it < kGaugeIterations; ++it) {
      Eigen::Matrix3d a = Eigen::Matrix3d::Identity() * 1e-9;
      Eigen::Vector3d b = Eigen::Vector3d::Zero();
      for (const std::size_t c : valid) {
        const double w = 1.0 / std::max((applied[c] + d[c] + jac[c] * shift).norm(), 1e-4);
        a += w * jac[c].transpose() * jac[c];
        b -= w * jac[c].transpose() * (applied[c] + d[c]);
      }
      const Eigen::Vector3d next = a.ldlt().solve(b);
      const bool settled = (next - shift).norm() < 1e-9;
      shift = next;
      if (settled) break;
    }
    for (const std::size_t c : valid) {
      const Eigen::Vector2d corrected = d[c] + jac[c] * shift;
      out[c][s].disparity = {corrected.x(), corrected.y()};
    }
  }
  return out;
}

std::unique_ptr<CameraModel> refit_with_offsets(const CameraModel& model, ImageSize image_size,
                                                const VolumeBounds& bounds,
                                                const std::function<Vec2d(const Vec3d&, const Vec2d&)>& offset,
                                                const std::string& camera_name, FitReport& report) {
  std::vector<PointCorrespondence> points;
  points.reserve(kLatticeXY * kLatticeXY * kLatticeZ);
  const Vec3d size = bounds.max - bounds.min;
  for (int k = 0; k < kLatticeZ; ++k)
    for (int j = 0; j < kLatticeXY; ++j)
      for (int i = 0; i < kLatticeXY; ++i) {
        const Vec3d world{bounds.min.x + size.x * i / (kLatticeXY - 1), bounds.min.y + size.y * j / (kLatticeXY - 1),
                          bounds.min.z + size.z * k / (kLatticeZ - 1)};
        const Vec2d pixel = model.project(world);
        const Vec2d o = offset(world, pixel);
        points.push_back({world, {pixel.x + o.x, pixel.y + o.y}});
      }
  FitOptions options;
  options.camera = camera_name;
  // A refractive camera keeps its window: the refit starts from it (pose fitted again).
  if (const auto* refractive = dynamic_cast<const RefractiveCamera*>(&model)) options.window = refractive->window();
  return fit_camera_model(model.model_name(), points, image_size, options, report);
}

CorrectionField::CorrectionField(const std::vector<SubvolumeDisparity>& corrections, const VolumeBounds& bounds,
                                 const std::string& camera_name)
    : centre_((bounds.min + bounds.max) * 0.5), half_size_((bounds.max - bounds.min) * 0.5) {
  std::vector<const SubvolumeDisparity*> valid;
  for (const auto& s : corrections)
    if (s.valid) valid.push_back(&s);
  if (valid.size() < 4)
    throw bad_input(fmt::format("{}: only {} sub-volume(s) hold enough particles to measure a disparity (at least 4 "
                                "needed); use more sets, a higher particle density, fewer sub-volumes or a larger "
                                "search radius",
                                camera_name, valid.size()));
  // Quadratic in x, y with z cross terms when each coefficient has two sub-volumes to go on.
  terms_ = valid.size() >= 18 ? 9 : 4;
  Eigen::MatrixXd a(static_cast<Eigen::Index>(valid.size()), static_cast<Eigen::Index>(terms_));
  Eigen::MatrixXd rhs(static_cast<Eigen::Index>(valid.size()), 2);
  std::vector<double> row(terms_);
  for (std::size_t n = 0; n < valid.size(); ++n) {
    basis(valid[n]->centroid, row.data());
    for (std::size_t t = 0; t < terms_; ++t) a(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(t)) = row[t];
    rhs(static_cast<Eigen::Index>(n), 0) = valid[n]->disparity.x;
    rhs(static_cast<Eigen::Index>(n), 1) = valid[n]->disparity.y;
  }
  // Rank-revealing: sub-volumes all in one z layer leave the z terms undetermined (zero).
  const Eigen::MatrixXd coefficients = a.completeOrthogonalDecomposition().solve(rhs);
  for (std::size_t t = 0; t < terms_; ++t) {
    cx_.push_back(coefficients(static_cast<Eigen::Index>(t), 0));
    cy_.push_back(coefficients(static_cast<Eigen::Index>(t), 1));
  }
}

void CorrectionField::basis(const Vec3d& world, double* out) const {
  const double u = (world.x - centre_.x) / half_size_.x, v = (world.y - centre_.y) / half_size_.y,
               w = (world.z - centre_.z) / half_size_.z;
  out[0] = 1;
  out[1] = u;
  out[2] = v;
  out[3] = w;
  if (terms_ == 4) return;
  out[4] = u * u;
  out[5] = u * v;
  out[6] = v * v;
  out[7] = u * w;
  out[8] = v * w;
}

Vec2d CorrectionField::at(const Vec3d& world) const {
  double row[9];
  basis(world, row);
  Vec2d out;
  for (std::size_t t = 0; t < terms_; ++t) {
    out.x += cx_[t] * row[t];
    out.y += cy_[t] * row[t];
  }
  return out;
}

}  // namespace tomorig::calibration::selfcal
