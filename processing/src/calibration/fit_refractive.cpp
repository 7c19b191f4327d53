// The refractive model (refractive_camera.h): a pinhole with lens distortion behind a flat
// window. Started from the pinhole fitted without the window; a first Levenberg-Marquardt
// pass fits the pinhole through the window at its given pose (no distortion), a second one
// everything free: pinhole, k1 k2 k3 p1 p2, the window's tilt and position if
// FitOptions::fit_window_pose, n_medium if FitOptions::fit_medium_index. The thickness and
// the other indices stay as given (they are not separable from the pose by the points).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <fmt/core.h>

#include "model_fits.h"
#include "projection_fit.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/refractive_camera.h"

namespace tomorig::calibration::detail {
namespace {

// Full parameter vector: pinhole (10: fx fy cx cy, rotation vector, t), distortion (5),
// window tilt (2, along two directions across the start normal), medium face (1), n_medium (1).
constexpr int kPinhole = 10, kDistortion = 5, kTilt = 2, kFace = 1, kIndex = 1;
constexpr int kAll = kPinhole + kDistortion + kTilt + kFace + kIndex;
constexpr int kDistortionAt = kPinhole, kTiltAt = kDistortionAt + kDistortion, kFaceAt = kTiltAt + kTilt,
              kIndexAt = kFaceAt + kFace;

struct Frame {
  FlatWindow start;
  Vec3d across1, across2;  // unit, perpendicular to start.normal and to each other
};

Frame frame_of(const FlatWindow& w) {
  Frame f{w, {}, {}};
  const Vec3d& n = w.normal;
  const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
  Vec3d a = helper - n * n.dot(helper);
  a = a * (1.0 / a.norm());
  const Vec3d b{n.y * a.z - n.z * a.y, n.z * a.x - n.x * a.z, n.x * a.y - n.y * a.x};
  f.across1 = a;
  f.across2 = b;
  return f;
}

FlatWindow window_of(const Eigen::VectorXd& q, const Frame& f) {
  FlatWindow w = f.start;
  Vec3d n = f.start.normal + f.across1 * q(kTiltAt) + f.across2 * q(kTiltAt + 1);
  w.normal = n * (1.0 / n.norm());
  w.medium_face_mm = q(kFaceAt);
  w.n_medium = q(kIndexAt);
  return w;
}

RefractiveCamera camera_of(const Eigen::VectorXd& q, const Frame& f) {
  const LensDistortion d{q(kDistortionAt), q(kDistortionAt + 1), q(kDistortionAt + 2), q(kDistortionAt + 3),
                         q(kDistortionAt + 4)};
  return RefractiveCamera(LensCamera(pinhole_of(q), d), window_of(q, f));
}

// LM over the parameters marked free in `free`; the others keep their values in `full`.
LmResult fit_subset(std::span<const PointCorrespondence> points, const Normalization& n, const Frame& frame,
                    const std::vector<int>& free, Eigen::VectorXd& full, const LmSettings& settings) {
  auto expand = [&](const Eigen::VectorXd& p) {
    Eigen::VectorXd q = full;
    for (std::size_t k = 0; k < free.size(); ++k) q(free[k]) = p(static_cast<int>(k));
    return q;
  };
  // camera_of throws for a step that puts the camera beyond the window (or an index below 1):
  // fit_projection takes that step as no candidate.
  const ProjectPoints project = [&](const Eigen::VectorXd& p, std::span<Vec2d> pixels) {
    const RefractiveCamera camera = camera_of(expand(p), frame);
    for (std::size_t i = 0; i < points.size(); ++i) pixels[i] = camera.project(points[i].world);
  };
  Eigen::VectorXd p(static_cast<int>(free.size()));
  for (std::size_t k = 0; k < free.size(); ++k) p(static_cast<int>(k)) = full(free[k]);
  const LmResult lm = fit_projection(points, n.image_scale, project, p, settings);
  full = expand(p);
  return lm;
}

}  // namespace

std::unique_ptr<CameraModel> fit_refractive(std::span<const PointCorrespondence> points, const FitOptions& options,
                                            FitReport& report) {
  if (!options.window)
    throw bad_input(fmt::format("{}: the refractive model needs the window: its thickness, indices and approximate pose "
                                "(--window-thickness, --indices, --window-face and --window-normal on the command line, FitOptions::window in "
                                "code)",
                                options.camera));
  if (const std::string problem = options.window->validate(); !problem.empty())
    throw bad_input(fmt::format("{}: window: {}", options.camera, problem));
  const int unknowns = kPinhole + kDistortion + (options.fit_window_pose ? kTilt + kFace : 0) + (options.fit_medium_index ? 1 : 0);
  check_points(points, {"refractive", unknowns, 2, 0}, options);

  // Start: the pinhole without the window (an apparent camera, close to the real one).
  const PinholeStart start = pinhole_start(points, options);
  const Normalization& n = start.normalization;
  Eigen::VectorXd full = Eigen::VectorXd::Zero(kAll);
  for (int i = 0; i < kPinhole; ++i) full(i) = start.parameters[static_cast<std::size_t>(i)];
  const Frame frame = frame_of(*options.window);
  full(kFaceAt) = options.window->medium_face_mm;
  full(kIndexAt) = options.window->n_medium;
  // The camera must start on the air side of the window.
  try {
    (void)camera_of(full, frame);
  } catch (const Error& e) {
    throw bad_input(fmt::format("{}: the refractive model cannot start: {}; check the window's position and normal "
                                "(it points from the cameras into the medium)",
                                options.camera, e.what()));
  }

  std::vector<int> free;
  for (int k = 0; k < kPinhole; ++k) free.push_back(k);
  const LmSettings settings = lm_settings(options);
  // Only a start for the full fit: a few tens of iterations bring the pinhole behind the window.
  LmSettings start_settings = settings;
  start_settings.max_iterations = std::min(settings.max_iterations, 30);
  start_settings.tolerance = std::max(settings.tolerance, 1e-6);
  fit_subset(points, n, frame, free, full, start_settings);
  for (int k = 0; k < kDistortion; ++k) free.push_back(kDistortionAt + k);
  if (options.fit_window_pose)
    for (int k = kTiltAt; k < kIndexAt; ++k) free.push_back(k);
  if (options.fit_medium_index) free.push_back(kIndexAt);
  const LmResult lm = fit_subset(points, n, frame, free, full, settings);
  check_fit(lm, static_cast<int>(free.size()), "refractive", "projection", options);
  report.normalization = n;
  report.iterations = lm.iterations;
  report.converged = lm.converged;
  return std::make_unique<RefractiveCamera>(camera_of(full, frame));
}

}  // namespace tomorig::calibration::detail
