#include "identifiability.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <Eigen/Dense>
#include <fmt/core.h>
#include <fmt/format.h>

#include "model_fits.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace tomorig::calibration::detail {
namespace {

// A unit column whose part outside the span of the lower-order columns is shorter than this
// is a combination of them on the points. Calibration points are design positions (exact to
// rounding), so a real dependency shows as ~1e-15; a well spread target as > 1e-2.
constexpr double kDependent = 1e-6;

struct Term {
  const char* name;
  int degree;
};

// Names of each basis's monomials in world coordinates, in the order of polynomial_maps.h.
std::vector<Term> term_names(Basis basis) {
  switch (basis) {
    case Basis::linear: return {{"x", 1}, {"y", 1}, {"z", 1}, {"1", 0}};
    case Basis::quadratic:
      return {{"x²", 2}, {"xy", 2}, {"xz", 2}, {"x", 1}, {"y²", 2}, {"yz", 2}, {"y", 1}, {"z²", 2}, {"z", 1}, {"1", 0}};
    case Basis::cubic:
      return {{"1", 0},   {"x", 1},   {"y", 1},   {"z", 1},   {"x²", 2},  {"y²", 2},  {"z²", 2},
              {"xy", 2},  {"xz", 2},  {"yz", 2},  {"x³", 3},  {"y³", 3},  {"z³", 3},  {"x²y", 3},
              {"x²z", 3}, {"xy²", 3}, {"y²z", 3}, {"xz²", 3}, {"xyz", 3}, {"yz²", 3}};
    case Basis::cubic_2d:
      return {{"1", 0}, {"x", 1}, {"y", 1}, {"x²", 2}, {"xy", 2}, {"y²", 2}, {"x³", 3}, {"x²y", 3}, {"xy²", 3}, {"y³", 3}};
  }
  return {};
}

// Which basis (and how many planes) a model of camera_model_names() needs.
struct ModelNeed {
  Basis basis;
  int min_planes;
  bool per_plane;
};
ModelNeed need_of(const std::string& model) {
  if (model == "rational2") return {Basis::quadratic, 3, false};
  if (model == "soloff3") return {Basis::cubic, 4, false};
  if (model == "twoplane") return {Basis::cubic_2d, 2, true};
  return {Basis::linear, 2, false};  // pinhole, dlt and the physical models built on a pinhole
}

// Determined models other than `model`, for advice ("pinhole or dlt").
std::string simpler_models(std::span<const PointCorrespondence> points, const Normalization& n, const std::string& model);

}  // namespace

BasisCheck check_basis(Basis basis, std::span<const PointCorrespondence> points, const Normalization& n) {
  const std::vector<Term> terms = term_names(basis);
  const int count = static_cast<int>(points.size());
  const int size = static_cast<int>(terms.size());
  Eigen::MatrixXd M(count, size);
  Terms m;
  for (int i = 0; i < count; ++i) {
    const Vec3d w = n.to_normalised(points[i].world);
    basis_terms(basis, w.x, w.y, w.z, m);
    for (int k = 0; k < size; ++k) M(i, k) = m[k];
  }
  // Columns by increasing degree (stable: the basis order within a degree).
  std::vector<int> order(size);
  for (int k = 0; k < size; ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return terms[a].degree < terms[b].degree; });

  BasisCheck check;
  std::vector<Eigen::VectorXd> accepted;  // orthonormal
  std::vector<int> accepted_terms;
  for (int k : order) {
    const double norm = M.col(k).norm();
    Eigen::VectorXd v = norm > 0 ? Eigen::VectorXd(M.col(k) / norm) : Eigen::VectorXd(M.col(k));
    for (int pass = 0; pass < 2; ++pass)  // Gram-Schmidt twice: orthogonal to rounding
      for (const auto& q : accepted) v -= q.dot(v) * q;
    if (norm > 0 && v.norm() > kDependent) {
      accepted.push_back(v / v.norm());
      accepted_terms.push_back(k);
      continue;
    }
    check.determined = false;
    check.undetermined_terms.push_back(terms[k].name);
    if (!check.combination.empty()) continue;
    // Which accepted terms it is made of: least squares over them, keeping the sizeable ones.
    Eigen::MatrixXd A(count, static_cast<int>(accepted_terms.size()));
    for (std::size_t j = 0; j < accepted_terms.size(); ++j) A.col(static_cast<int>(j)) = M.col(accepted_terms[j]);
    std::vector<std::string> parts;
    if (A.cols() > 0) {
      const Eigen::VectorXd c = A.colPivHouseholderQr().solve(M.col(k));
      const double largest = c.cwiseAbs().maxCoeff();
      for (int j = 0; j < c.size(); ++j)
        if (std::abs(c(j)) > 1e-6 * largest) parts.push_back(terms[accepted_terms[static_cast<std::size_t>(j)]].name);
    }
    check.combination = parts.empty() ? fmt::format("{} vanishes on them", terms[k].name)
                                      : fmt::format("{} is a combination of {}", terms[k].name, fmt::join(parts, ", "));
  }
  return check;
}

std::string describe_layout(std::span<const PointCorrespondence> points) {
  // Lines along world axis a: the points group by their other two coordinates.
  double extent = 0;
  for (const auto& p : points) extent = std::max({extent, std::abs(p.world.x), std::abs(p.world.y), std::abs(p.world.z)});
  const double tolerance = 1e-6 * std::max(extent, 1.0);
  static const char* axis_names[] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    std::map<std::pair<long long, long long>, int> lines;
    for (const auto& p : points) {
      const double c[3] = {p.world.x, p.world.y, p.world.z};
      const double a = c[(axis + 1) % 3], b = c[(axis + 2) % 3];
      ++lines[{std::llround(a / tolerance), std::llround(b / tolerance)}];
    }
    const bool every_line_has_points = std::all_of(lines.begin(), lines.end(), [](const auto& l) { return l.second >= 2; });
    if (lines.size() >= 2 && every_line_has_points && 3 * lines.size() <= points.size())
      return fmt::format("the {} points lie on {} lines parallel to {}", points.size(), lines.size(), axis_names[axis]);
  }
  return fmt::format("the {} points do not fill the volume (they lie on a few lines or on a curved surface)",
                     points.size());
}

std::vector<std::string> determined_models(std::span<const PointCorrespondence> points, const Normalization& n) {
  const std::vector<Plane> planes = group_by_plane(points);
  std::vector<std::string> out;
  for (const std::string& model : camera_model_names()) {
    const ModelNeed need = need_of(model);
    if (static_cast<int>(planes.size()) < need.min_planes) continue;
    bool ok = true;
    if (need.per_plane) {
      for (const Plane& plane : planes) {
        if (plane.points.size() < 10) ok = false;
        else if (!check_basis(need.basis, plane.points, compute_normalization(plane.points)).determined) ok = false;
      }
    } else {
      ok = check_basis(need.basis, points, n).determined;
    }
    if (ok) out.push_back(model);
  }
  return out;
}

void require_determined(Basis basis, const std::string& model, std::span<const PointCorrespondence> points,
                        const Normalization& n, const FitOptions& options) {
  const BasisCheck check = check_basis(basis, points, n);
  if (check.determined) return;
  std::vector<std::string> terms = check.undetermined_terms;
  const std::size_t all = terms.size();
  if (terms.size() > 6) terms.resize(6);
  const std::string term_list = fmt::format("{}{}", fmt::join(terms, ", "), all > terms.size() ? fmt::format(" and {} more", all - terms.size()) : "");
  const std::vector<std::string> usable = determined_models(points, n);
  const std::string advice =
      usable.empty() ? "spread the points over the volume (more planes, points off these lines)"
                     : fmt::format("use {} (which these points determine), or add points off these lines and planes",
                                   fmt::join(usable, " or "));
  throw bad_input(fmt::format("{}: the points do not determine the {} model: {}: the {} {} not determined (on these "
                              "points {}), so the model is arbitrary between the points; {}",
                              options.camera, model, describe_layout(points), term_list, all == 1 ? "term is" : "terms are",
                              check.combination, advice));
}

namespace {
std::string simpler_models(std::span<const PointCorrespondence> points, const Normalization& n, const std::string& model) {
  std::vector<std::string> usable;
  for (const std::string& m : determined_models(points, n))
    if (m != model) usable.push_back(m);
  if (usable.empty()) usable = {"pinhole", "dlt"};
  return fmt::format("{}", fmt::join(usable, " or "));
}
}  // namespace

void require_one_signed_denominator(const MapForm& form, const std::vector<double>& coefficients,
                                    const MapSamples& samples, const std::string& model, const std::string& what,
                                    const Normalization& n, bool world_inputs, std::span<const PointCorrespondence> points,
                                    const FitOptions& options) {
  const auto& inputs = samples.inputs;
  if (!form.rational || inputs.empty()) return;
  std::array<double, 3> lo = inputs.front(), hi = inputs.front();
  for (const auto& in : inputs)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], in[k]), hi[k] = std::max(hi[k], in[k]);
  // Outputs beyond this (normalised units) are not an image of the calibrated box.
  double largest_target = 0;
  for (const Vec2d& t : samples.targets) largest_target = std::max(largest_target, std::hypot(t.x, t.y));
  const double bound = 10 * (1 + largest_target);
  const int nb = basis_size(form.basis);
  const double* d = coefficients.data() + 2 * nb;
  auto denominator = [&](const std::array<double, 3>& x) {
    Terms m;
    basis_terms(form.basis, x[0], x[1], x[2], m);
    double sum = 0;
    for (int k = 0; k < nb; ++k) sum += d[k] * m[k];
    return sum;
  };
  auto along = [](const std::array<double, 3>& a, double s) { return std::array<double, 3>{a[0] * s, a[1] * s, a[2] * s}; };
  // The sign at the centroid of the points (the normalised origin) is the model's own.
  const double reference = denominator({0, 0, 0});
  constexpr int kSteps = 16;  // 17^3 lattice over the box, corners and faces included
  int examined = 0;
  for (int i = 0; i <= kSteps; ++i)
    for (int j = 0; j <= kSteps; ++j)
      for (int k = 0; k <= kSteps && examined < 64; ++k) {
        const std::array<double, 3> x{lo[0] + (hi[0] - lo[0]) * i / kSteps, lo[1] + (hi[1] - lo[1]) * j / kSteps,
                                      lo[2] + (hi[2] - lo[2]) * k / kSteps};
        if (denominator(x) * reference > 0) continue;
        ++examined;
        // Where the denominator vanishes between the centroid and x (bisection on the segment).
        double a = 0, b = 1;
        for (int step = 0; step < 60; ++step) {
          const double mid = 0.5 * (a + b);
          (denominator(along(x, mid)) * reference > 0 ? a : b) = mid;
        }
        // A zero shared with the numerators (a common factor of the ratio, which the fit of a
        // ratio is free to pick up) leaves the mapping finite across it: no pole. A true pole
        // sends the mapping far beyond the image on either side.
        const double c = 0.5 * (a + b);
        double worst = 0;
        for (const double side : {c - 1e-4, c + 1e-4}) {
          const auto p = along(x, side);
          const Vec2d out = evaluate_map(form, coefficients.data(), p[0], p[1], p[2]);
          worst = std::max(worst, std::isfinite(out.x) && std::isfinite(out.y) ? std::hypot(out.x, out.y) : HUGE_VAL);
        }
        if (worst < bound) continue;
        const auto pole = along(x, c);
        std::string where;
        if (world_inputs) {
          const Vec3d w = n.to_world({pole[0], pole[1], pole[2]});
          where = fmt::format("world ({:.4g}, {:.4g}, {:.4g}) mm", w.x, w.y, w.z);
        } else {
          const Vec2d px = n.to_pixel({pole[0], pole[1]});
          where = fmt::format("pixel ({:.1f}, {:.1f}) at z = {:.4g} mm", px.x, px.y, pole[2] * n.world_scale + n.world_centre.z);
        }
        throw bad_input(fmt::format("{}: the fitted {} {} has a pole inside the calibrated box: its denominator changes "
                                    "sign near {}, so it maps points there far from where the camera sees them; the "
                                    "points do not determine this model well enough; use {} or spread the points over "
                                    "the volume",
                                    options.camera, model, what, where, simpler_models(points, n, model)));
      }
}

}  // namespace tomorig::calibration::detail
