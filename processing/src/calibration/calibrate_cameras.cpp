#include "tomorig/processing/calibration/calibrate_cameras.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include <fmt/core.h>
#include <fmt/format.h>

#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/traverse_correction.h"

namespace tomorig::calibration {

std::vector<PlaneResidual> plane_residuals(const CameraModel& model, std::span<const PointCorrespondence> points) {
  std::map<double, std::vector<PointCorrespondence>> by_z;
  for (const auto& p : points) by_z[p.world.z].push_back(p);
  std::vector<PlaneResidual> planes;
  for (const auto& [z, plane_points] : by_z) {
    FitReport report;
    measure_residuals(model, plane_points, report);
    planes.push_back({z, static_cast<int>(plane_points.size()), report.forward_mean_px, report.reverse_mean_um});
  }
  return planes;
}

CrossValidation cross_validate(const std::string& model, std::span<const PointCorrespondence> points, ImageSize size,
                               const FitOptions& options, int camera, LeaveOut left_out) {
  CrossValidation cv;
  cv.camera = camera;
  cv.model = model;
  cv.left_out = left_out;
  // Folds: the indices of the points left out together (one plane, or one point).
  std::vector<std::vector<std::size_t>> folds;
  if (left_out == LeaveOut::plane) {
    std::map<double, std::vector<std::size_t>> by_z;
    for (std::size_t k = 0; k < points.size(); ++k) by_z[points[k].world.z].push_back(k);
    for (auto& [z, indices] : by_z) folds.push_back(std::move(indices));
  } else {
    for (std::size_t k = 0; k < points.size(); ++k) folds.push_back({k});
  }
  double squares = 0;
  std::vector<bool> out(points.size(), false);
  for (const std::vector<std::size_t>& fold : folds) {
    for (std::size_t k : fold) out[k] = true;
    std::vector<PointCorrespondence> kept;
    kept.reserve(points.size());
    for (std::size_t k = 0; k < points.size(); ++k)
      if (!out[k]) kept.push_back(points[k]);
    for (std::size_t k : fold) out[k] = false;
    try {
      FitReport report;
      const auto fitted = fit_camera_model(model, kept, size, options, report);
      for (std::size_t k : fold) {
        const Vec2d u = fitted->project(points[k].world);
        const double d = std::hypot(u.x - points[k].pixel.x, u.y - points[k].pixel.y);
        squares += d * d;
        cv.max_px = std::max(cv.max_px, d);
        ++cv.points;
      }
      ++cv.folds;
    } catch (const Error& e) {
      const auto& first = points[fold.front()];
      cv.error = left_out == LeaveOut::plane
                     ? fmt::format("without plane z = {} mm: {}", first.world.z, e.what())
                     : fmt::format("without the point ({}, {}, {}) mm: {}", first.world.x, first.world.y, first.world.z,
                                   e.what());
      return cv;
    }
  }
  cv.rms_px = cv.points > 0 ? std::sqrt(squares / cv.points) : 0;
  return cv;
}

AutoChoice choose_model(const std::vector<CrossValidation>& results, const std::vector<std::string>& models) {
  std::vector<std::pair<double, std::string>> ranked;
  for (const std::string& model : models) {
    double sum = 0;
    int cameras = 0;
    bool usable = true;
    for (const CrossValidation& cv : results)
      if (cv.model == model) {
        usable = usable && cv.error.empty();
        sum += cv.rms_px;
        ++cameras;
      }
    if (usable && cameras > 0) ranked.push_back({sum / cameras, model});
  }
  if (ranked.empty())
    throw bad_input("--models auto: no model could be cross-validated on every camera (each needs its planes; see the "
                    "reasons above); list the models with --models");
  std::sort(ranked.begin(), ranked.end());
  AutoChoice choice{ranked.front().second, {}};
  const bool by_point = !results.empty() && results.front().left_out == LeaveOut::point;
  choice.reason = fmt::format("stored {}: the lowest leave-one-{}-out RMS, {:.4g} px averaged over the cameras", choice.model,
                              by_point ? "point" : "plane", ranked.front().first);
  if (ranked.size() > 1)
    choice.reason += fmt::format(" (next: {} {:.4g} px)", ranked[1].second, ranked[1].first);
  return choice;
}

std::string CalibrateCamerasReport::failure_message() const {
  if (!stored_failure) return {};
  std::vector<int> cameras;
  for (const ModelResult& r : results)
    if (!r.error.empty() && r.report.model == stored) cameras.push_back(r.camera);
  return fmt::format("no calibration written: the stored model {} failed for camera {} (reasons above); store another "
                     "model with --store, or fix the points",
                     stored, fmt::join(cameras, ", "));
}

std::vector<std::string> CalibrateCamerasReport::poor_fit_warnings() const {
  std::vector<std::string> out;
  for (const auto& c : calibrations)
    if (std::string warning = rms_warning(c); !warning.empty()) out.push_back(std::move(warning));
  return out;
}

CalibrateCamerasReport calibrate_cameras(std::span<const std::vector<PointCorrespondence>> points,
                                         std::span<const ImageSize> sizes, const CalibrateCamerasOptions& options) {
  if (points.size() != sizes.size())
    throw bad_input(fmt::format("calibrate: {} cameras of points but {} image sizes", points.size(), sizes.size()));
  if (options.models.empty()) throw bad_input("calibrate: no camera model to fit");
  const std::vector<std::string>& models = options.models;
  const auto notice = [&](const std::string& text) {
    if (options.notice) options.notice(text);
  };
  CalibrateCamerasReport out;
  out.stored = options.stored;

  // With the traverse correction, every model is fitted to the corrected points
  // (docs/calibration.md, "Traverse-error correction"); the last model of the list comes from
  // the correction itself.
  std::optional<TraverseCorrectionResult> traverse;
  if (options.stage_correction) {
    TraverseCorrectionOptions correction;
    correction.final_model = models.back();
    correction.camera_names = options.camera_names;
    correction.fit = options.fit;
    traverse = correct_traverse(points, sizes, correction);
  }

  const auto fit_options = [&](std::size_t camera) {
    FitOptions fit = options.fit;
    fit.camera = fmt::format("camera {}", camera);
    return fit;
  };
  const auto points_of = [&](std::size_t camera) -> const std::vector<PointCorrespondence>& {
    return traverse ? traverse->corrected_points[camera] : points[camera];
  };
  if (options.cross_validate || options.choose_model) {
    for (std::size_t i = 0; i < points.size(); ++i)
      for (const std::string& model_name : models)
        out.validation.push_back(
            cross_validate(model_name, points_of(i), sizes[i], fit_options(i), static_cast<int>(i), options.leave_out));
    if (options.choose_model) {
      const AutoChoice choice = choose_model(out.validation, models);
      out.stored = choice.model;
      notice(fmt::format("--models auto: {}", choice.reason));
    }
  }

  for (std::size_t i = 0; i < points.size(); ++i) {
    const FitOptions fit = fit_options(i);
    const std::vector<PointCorrespondence>& camera_points = points_of(i);
    for (const std::string& model_name : models) {
      FitReport report;
      report.model = model_name;
      report.camera = fit.camera;
      std::unique_ptr<CameraModel> model;
      try {
        if (traverse && model_name == models.back()) {
          model = std::move(traverse->models[i]);
          report = traverse->reports[i];
        } else {
          model = fit_camera_model(model_name, camera_points, sizes[i], fit, report);
        }
      } catch (const Error& e) {
        notice(fmt::format("{} {}: {}: {}", model_name == out.stored ? "error" : "warning", model_name,
                           e.kind() == ErrorKind::bad_input ? "refused" : "failed", e.what()));
        ModelResult failed{static_cast<int>(i), report, {}};
        failed.error = e.what();
        out.results.push_back(std::move(failed));
        if (model_name == out.stored && !out.stored_failure) out.stored_failure = e.kind();
        continue;
      }
      std::vector<PlaneResidual> planes = plane_residuals(*model, camera_points);
      // Corrected points sit at nominal z + offset; report the planes by their nominal z.
      if (traverse && planes.size() == traverse->plane_z_mm.size())
        for (std::size_t k = 0; k < planes.size(); ++k) planes[k].z_mm = traverse->plane_z_mm[k];
      out.results.push_back({static_cast<int>(i), report, std::move(planes)});
      if (model_name == out.stored) out.calibrations.push_back({static_cast<int>(i), sizes[i], std::move(model), report});
    }
  }
  if (traverse)
    out.offsets = StageOffsets{traverse->plane_z_mm, traverse->offsets_mm, traverse->per_camera_offsets_mm,
                               options.camera_names, traverse->cycles, traverse->converged};
  return out;
}

}  // namespace tomorig::calibration
