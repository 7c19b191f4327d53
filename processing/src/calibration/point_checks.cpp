// Input checks shared by the model fits: each failure names the camera and, where it applies,
// the plane, and says what would make the data usable.
#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>
#include <fmt/core.h>
#include <fmt/format.h>

#include "identifiability.h"
#include "model_fits.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration::detail {
namespace {

constexpr double kSamePlaneMm = 1e-6;
// Eigenvalue ratio of a normalised point cloud's scatter below which it has lost a dimension.
constexpr double kFlat = 1e-12;
// Column-scaled J^T J eigenvalue ratio below which a parameter is not determined by the data.
constexpr double kUndetermined = 1e-18;

std::string plane_list(const std::vector<Plane>& planes) {
  std::string list;
  for (std::size_t k = 0; k < planes.size() && k < 8; ++k) list += fmt::format("{}{}", k ? ", " : "", planes[k].z);
  if (planes.size() > 8) list += ", ...";
  return list + " mm";
}

// Eigenvalues (ascending) of the scatter matrix of 2-D or 3-D points, normalised by the largest.
template <int D>
Eigen::Matrix<double, D, 1> scatter_ratios(const std::vector<Eigen::Matrix<double, D, 1>>& pts) {
  Eigen::Matrix<double, D, 1> mean = Eigen::Matrix<double, D, 1>::Zero();
  for (const auto& p : pts) mean += p / static_cast<double>(pts.size());
  Eigen::Matrix<double, D, D> s = Eigen::Matrix<double, D, D>::Zero();
  for (const auto& p : pts) s += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, D, D>> eig(s, Eigen::EigenvaluesOnly);
  Eigen::Matrix<double, D, 1> ev = eig.eigenvalues();
  const double largest = ev(D - 1);
  return largest > 0 ? Eigen::Matrix<double, D, 1>(ev / largest) : Eigen::Matrix<double, D, 1>::Zero();
}

bool image_collinear(std::span<const PointCorrespondence> points) {
  std::vector<Eigen::Vector2d> image;
  for (const auto& p : points) image.emplace_back(p.pixel.x, p.pixel.y);
  return scatter_ratios<2>(image)(0) < kFlat;
}

bool world_collinear_2d(std::span<const PointCorrespondence> points) {
  std::vector<Eigen::Vector2d> xy;
  for (const auto& p : points) xy.emplace_back(p.world.x, p.world.y);
  return scatter_ratios<2>(xy)(0) < kFlat;
}

}  // namespace

std::vector<Plane> group_by_plane(std::span<const PointCorrespondence> points) {
  std::vector<PointCorrespondence> sorted(points.begin(), points.end());
  std::stable_sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) { return a.world.z < b.world.z; });
  std::vector<Plane> planes;
  for (const auto& p : sorted) {
    if (planes.empty() || p.world.z - planes.back().points.back().world.z > kSamePlaneMm) planes.push_back({p.world.z, {}});
    planes.back().points.push_back(p);
  }
  // A plane's z is its first (lowest) point's: exact for stage positions, and printable.
  for (auto& plane : planes) plane.z = plane.points.front().world.z;
  return planes;
}

LmSettings lm_settings(const FitOptions& options) { return {options.max_iterations, options.tolerance}; }

Normalization check_points(std::span<const PointCorrespondence> points, const Requirements& req, const FitOptions& options) {
  const std::string& cam = options.camera;
  if (const std::string problem = options.validate(); !problem.empty())
    throw bad_input(fmt::format("{}: fit options: {}", cam, problem));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto& p = points[i];
    if (!std::isfinite(p.world.x) || !std::isfinite(p.world.y) || !std::isfinite(p.world.z) ||
        !std::isfinite(p.pixel.x) || !std::isfinite(p.pixel.y))
      throw bad_input(fmt::format("{}: point {} has a non-finite coordinate (world ({}, {}, {}), pixel ({}, {}))", cam, i,
                                  p.world.x, p.world.y, p.world.z, p.pixel.x, p.pixel.y));
  }
  const int needed = (req.unknowns + 1) / 2;
  if (static_cast<int>(points.size()) < needed)
    throw bad_input(fmt::format("{}: too few points for the {} model: {} given, at least {} needed ({} unknowns, 2 "
                                "equations per point); detect more target points or choose a simpler model",
                                cam, req.model, points.size(), needed, req.unknowns));

  std::vector<Eigen::Vector3d> world;
  for (const auto& p : points) world.emplace_back(p.world.x, p.world.y, p.world.z);
  const Eigen::Vector3d w = scatter_ratios<3>(world);
  if (w(1) < kFlat)
    throw bad_input(fmt::format("{}: degenerate geometry for the {} model: all {} world points are collinear (or "
                                "coincide); the target must span an area on each plane",
                                cam, req.model, points.size()));
  if (image_collinear(points))
    throw bad_input(fmt::format("{}: degenerate geometry for the {} model: all {} image points are collinear; check "
                                "the point detection for this camera",
                                cam, req.model, points.size()));
  const std::vector<Plane> planes = group_by_plane(points);
  if (planes.size() == 1)
    throw bad_input(fmt::format("{}: all {} points lie on one plane (z = {} mm); the {} model needs depth: give points on "
                                "at least {} planes at different z",
                                cam, points.size(), planes.front().z, req.model, req.min_planes));
  if (w(0) < kFlat)
    throw bad_input(fmt::format("{}: all {} points lie on one (tilted) plane; the {} model needs depth: give points on "
                                "at least {} planes at different z",
                                cam, points.size(), req.model, req.min_planes));
  if (static_cast<int>(planes.size()) < req.min_planes) {
    // Say which terms the planes leave open too, so that points on lines are recognised.
    std::string terms;
    if (req.basis) {
      const BasisCheck check = check_basis(*req.basis, points, compute_normalization(points));
      if (!check.determined) {
        std::vector<std::string> list = check.undetermined_terms;
        if (list.size() > 6) list.resize(6);
        terms = fmt::format("; {}: the {}{} terms are not determined", describe_layout(points), fmt::join(list, ", "),
                            check.undetermined_terms.size() > list.size() ? " and more" : "");
      }
    }
    throw bad_input(fmt::format("{}: the points lie on {} planes (z = {}); the {} model needs at least {} planes at "
                                "different z{}",
                                cam, planes.size(), plane_list(planes), req.model, req.min_planes, terms));
  }
  if (req.min_points_per_plane > 0)
    for (std::size_t k = 0; k < planes.size(); ++k) {
      const Plane& plane = planes[k];
      if (static_cast<int>(plane.points.size()) < req.min_points_per_plane)
        throw bad_input(fmt::format("{}, plane {} (z = {} mm): too few points for the {} model: {} given, at least {} "
                                    "needed on every plane",
                                    cam, k, plane.z, req.model, plane.points.size(), req.min_points_per_plane));
      if (world_collinear_2d(plane.points) || image_collinear(plane.points))
        throw bad_input(fmt::format("{}, plane {} (z = {} mm): degenerate geometry for the {} model: the points of this "
                                    "plane are collinear",
                                    cam, k, plane.z, req.model));
    }
  const Normalization n = compute_normalization(points);
  if (req.basis) require_determined(*req.basis, req.model, points, n, options);
  return n;
}

void check_fit(const LmResult& lm, int parameters, const std::string& model, const std::string& what,
               const FitOptions& options, bool identifiable) {
  if (identifiable && lm.conditioning < kUndetermined)
    throw bad_input(fmt::format("{}: degenerate geometry for the {} model: the points do not determine all {} "
                                "coefficients of the {} (conditioning {:.2g}); spread the points over the image and "
                                "over more planes",
                                options.camera, model, parameters, what, lm.conditioning));
  if (!lm.converged && options.require_convergence)
    throw runtime_error(fmt::format("{}: the {} fit of the {} did not converge in {} iterations (sum of squared "
                                    "residuals {:.3g}, normalised units); check the correspondences for outliers, or allow more "
                                    "iterations (--max-iterations on the command line, FitOptions::max_iterations in code)",
                                    options.camera, model, what, lm.iterations, lm.cost));
}

}  // namespace tomorig::calibration::detail
