// Traverse-error correction (thesis Sect. 6.3.3): alternate per-plane offset estimates by
// disparity minimisation with re-fits of the alternation model (the pinhole, or the refractive
// model behind a window), then fit the final model.
#include "tomorig/processing/calibration/traverse_correction.h"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"

namespace tomorig::calibration {

namespace {

constexpr double kSameZ = 1e-6;  // mm: points of one plane share z within this

// Index of the plane with nominal z `z`, or -1.
int plane_of(std::span<const double> planes, double z) {
  for (std::size_t k = 0; k < planes.size(); ++k)
    if (std::abs(planes[k] - z) <= kSameZ) return static_cast<int>(k);
  return -1;
}

struct Observation {
  const CameraModel* camera;
  Vec3d world;  // current (corrected) world point
  Vec2d pixel;
};

// Solves the 3 x 3 system A x = b (A symmetric positive semi-definite); false if singular.
bool solve3(const double A[3][3], const double b[3], double x[3]) {
  double M[3][4];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) M[r][c] = A[r][c];
    M[r][3] = b[r];
  }
  for (int c = 0; c < 3; ++c) {
    int p = c;
    for (int r = c + 1; r < 3; ++r)
      if (std::abs(M[r][c]) > std::abs(M[p][c])) p = r;
    if (std::abs(M[p][c]) < 1e-300) return false;
    std::swap(M[p], M[c]);
    for (int r = 0; r < 3; ++r) {
      if (r == c) continue;
      const double f = M[r][c] / M[c][c];
      for (int k = c; k < 4; ++k) M[r][k] -= f * M[c][k];
    }
  }
  for (int r = 0; r < 3; ++r) x[r] = M[r][3] / M[r][r];
  return true;
}

// The shift d minimising sum |project(world + d) - pixel|^2 over the observations (Gauss-
// Newton, central-difference Jacobian). The models are smooth; a few steps converge.
Vec3d best_shift(const std::vector<Observation>& obs) {
  Vec3d d{0, 0, 0};
  constexpr double h = 1e-4;  // mm
  for (int iteration = 0; iteration < 8; ++iteration) {
    double A[3][3] = {}, b[3] = {};
    for (const Observation& o : obs) {
      const Vec3d w = o.world + d;
      const Vec2d p = o.camera->project(w);
      const double r[2] = {p.x - o.pixel.x, p.y - o.pixel.y};
      double J[2][3];
      for (int a = 0; a < 3; ++a) {
        Vec3d e{0, 0, 0};
        (a == 0 ? e.x : a == 1 ? e.y : e.z) = h;
        const Vec2d pp = o.camera->project(w + e), pm = o.camera->project(w - e);
        J[0][a] = (pp.x - pm.x) / (2 * h);
        J[1][a] = (pp.y - pm.y) / (2 * h);
      }
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) A[i][j] += J[0][i] * J[0][j] + J[1][i] * J[1][j];
        b[i] -= J[0][i] * r[0] + J[1][i] * r[1];
      }
    }
    double step[3];
    if (!solve3(A, b, step)) break;
    d = d + Vec3d{step[0], step[1], step[2]};
    if (std::abs(step[0]) + std::abs(step[1]) + std::abs(step[2]) < 1e-9) break;
  }
  return d;
}

std::string camera_name(const TraverseCorrectionOptions& o, std::size_t c) {
  return c < o.camera_names.size() ? o.camera_names[c] : fmt::format("camera {}", c + 1);
}

}  // namespace

std::string alternation_model_for(const std::string& final_model) {
  return final_model == "refractive" ? "refractive" : "pinhole";
}

void remove_gauge(std::span<Vec3d> offsets_mm, std::span<const double> plane_z_mm, bool remove_y_trend) {
  const std::size_t n = offsets_mm.size();
  if (n == 0 || plane_z_mm.size() != n) return;
  double zm = 0;
  Vec3d mean{0, 0, 0};
  for (std::size_t k = 0; k < n; ++k) zm += plane_z_mm[k] / n, mean = mean + offsets_mm[k] * (1.0 / n);
  double szz = 0;
  Vec3d s_offset_z{0, 0, 0};
  for (std::size_t k = 0; k < n; ++k) {
    const double dz = plane_z_mm[k] - zm;
    szz += dz * dz;
    s_offset_z = s_offset_z + (offsets_mm[k] - mean) * dz;
  }
  Vec3d slope = szz > 0 ? s_offset_z * (1.0 / szz) : Vec3d{0, 0, 0};
  if (!remove_y_trend) slope.y = 0;
  for (std::size_t k = 0; k < n; ++k) offsets_mm[k] = offsets_mm[k] - mean - slope * (plane_z_mm[k] - zm);
}

std::string TraverseCorrectionOptions::validate() const {
  if (max_cycles < 1) return fmt::format("traverse correction: max_cycles = {} must be >= 1", max_cycles);
  if (!(tolerance_um > 0) || !std::isfinite(tolerance_um))
    return fmt::format("traverse correction: tolerance_um = {} must be > 0", tolerance_um);
  const auto& names = all_camera_model_names();
  if (std::find(names.begin(), names.end(), final_model) == names.end())
    return fmt::format("traverse correction: final_model '{}' is unknown; known models: {}", final_model,
                       fmt::join(names, ", "));
  if (final_model == "refractive" && !fit.window)
    return "traverse correction: the refractive final model needs the window (FitOptions::window; --window-thickness "
           "and its companions on the command line)";
  return fit.validate();
}

std::vector<PointCorrespondence> apply_plane_offsets(std::span<const PointCorrespondence> points,
                                                     std::span<const double> plane_z_mm,
                                                     std::span<const Vec3d> offsets_mm) {
  if (plane_z_mm.size() != offsets_mm.size())
    throw bad_input(fmt::format("apply_plane_offsets: {} plane heights but {} offsets", plane_z_mm.size(),
                                offsets_mm.size()));
  std::vector<PointCorrespondence> out(points.begin(), points.end());
  for (PointCorrespondence& p : out) {
    const int k = plane_of(plane_z_mm, p.world.z);
    if (k < 0) throw bad_input(fmt::format("apply_plane_offsets: a point at z = {} mm lies on no listed plane", p.world.z));
    p.world = p.world + offsets_mm[static_cast<std::size_t>(k)];
  }
  return out;
}

TraverseCorrectionResult correct_traverse(std::span<const std::vector<PointCorrespondence>> points_per_camera,
                                          std::span<const ImageSize> image_sizes,
                                          const TraverseCorrectionOptions& options) {
  if (const std::string problem = options.validate(); !problem.empty()) throw bad_input(problem);
  const std::size_t cameras = points_per_camera.size();
  if (cameras < 2)
    throw bad_input(fmt::format("traverse correction needs at least 2 cameras (got {}): one camera cannot tell a "
                                "plane offset from its own pose",
                                cameras));
  if (image_sizes.size() != cameras)
    throw bad_input(fmt::format("traverse correction: {} cameras but {} image sizes", cameras, image_sizes.size()));

  TraverseCorrectionResult result;
  for (const auto& pts : points_per_camera)
    for (const PointCorrespondence& p : pts)
      if (plane_of(result.plane_z_mm, p.world.z) < 0) result.plane_z_mm.push_back(p.world.z);
  std::sort(result.plane_z_mm.begin(), result.plane_z_mm.end());
  const std::size_t planes = result.plane_z_mm.size();
  if (planes < 2)
    throw bad_input(fmt::format("traverse correction needs points on at least 2 planes (got {})", planes));
  for (std::size_t c = 0; c < cameras; ++c)
    if (points_per_camera[c].empty())
      throw bad_input(fmt::format("traverse correction: {} has no points", camera_name(options, c)));

  result.alternation_model = alternation_model_for(options.final_model);
  std::vector<Vec3d> offsets(planes, Vec3d{0, 0, 0});
  auto refit = [&](std::vector<std::unique_ptr<CameraModel>>& models, std::vector<FitReport>& reports) {
    models.clear();
    reports.assign(cameras, {});
    result.corrected_points.clear();
    for (std::size_t c = 0; c < cameras; ++c) {
      result.corrected_points.push_back(apply_plane_offsets(points_per_camera[c], result.plane_z_mm, offsets));
      FitOptions fo = options.fit;
      fo.camera = camera_name(options, c);
      models.push_back(
          fit_camera_model(result.alternation_model, result.corrected_points.back(), image_sizes[c], fo, reports[c]));
    }
  };
  // The shift of plane k that best explains the disparities of the given cameras.
  auto plane_shifts = [&](const std::vector<std::unique_ptr<CameraModel>>& models, std::size_t only_camera) {
    std::vector<Vec3d> shifts(planes);
    for (std::size_t k = 0; k < planes; ++k) {
      std::vector<Observation> obs;
      for (std::size_t c = 0; c < cameras; ++c) {
        if (only_camera < cameras && c != only_camera) continue;
        for (const PointCorrespondence& p : result.corrected_points[c])
          if (std::abs(p.world.z - (result.plane_z_mm[k] + offsets[k].z)) <= kSameZ + 1e-9)
            obs.push_back({models[c].get(), p.world, p.pixel});
      }
      shifts[k] = obs.size() >= 3 ? best_shift(obs) : Vec3d{0, 0, 0};
    }
    return shifts;
  };
  const bool y_trend_is_gauge = result.alternation_model == "refractive";
  auto remove_mean = [&](std::vector<Vec3d>& v) { remove_gauge(v, result.plane_z_mm, y_trend_is_gauge); };

  for (result.cycles = 1; result.cycles <= options.max_cycles; ++result.cycles) {
    refit(result.alternation_models, result.alternation_reports);
    std::vector<Vec3d> shifts = plane_shifts(result.alternation_models, cameras);
    remove_mean(shifts);
    double largest = 0;
    for (std::size_t k = 0; k < planes; ++k) {
      offsets[k] = offsets[k] + shifts[k];
      largest = std::max({largest, std::abs(shifts[k].x), std::abs(shifts[k].y), std::abs(shifts[k].z)});
    }
    if (largest * 1e3 < options.tolerance_um) {
      result.converged = true;
      break;
    }
  }
  result.cycles = std::min(result.cycles, options.max_cycles);
  refit(result.alternation_models, result.alternation_reports);
  result.offsets_mm = offsets;

  for (std::size_t c = 0; c < cameras; ++c) {
    std::vector<Vec3d> own = plane_shifts(result.alternation_models, c);
    remove_mean(own);
    for (std::size_t k = 0; k < planes; ++k) own[k] = own[k] + offsets[k];
    result.per_camera_offsets_mm.push_back(std::move(own));
  }

  result.reports.assign(cameras, {});
  for (std::size_t c = 0; c < cameras; ++c) {
    FitOptions fo = options.fit;
    fo.camera = camera_name(options, c);
    if (options.final_model == result.alternation_model) {
      result.models.push_back(result.alternation_models[c]->clone());
      result.reports[c] = result.alternation_reports[c];
    } else {
      result.models.push_back(
          fit_camera_model(options.final_model, result.corrected_points[c], image_sizes[c], fo, result.reports[c]));
    }
  }
  return result;
}

}  // namespace tomorig::calibration
