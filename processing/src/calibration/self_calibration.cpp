// Volume self-calibration: the iteration of triangulation, disparity measurement and
// correction (self_calibration.h), and its checks.
#include "tomorig/processing/calibration/self_calibration.h"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "self_calibration_internal.h"
#include "tomorig/core/error.h"

namespace tomorig::calibration {
namespace {

using selfcal::PeakIndex;

std::string camera_name(const SelfCalibrationOptions& options, std::size_t c) {
  return c < options.camera_names.size() ? options.camera_names[c] : fmt::format("camera {}", c);
}

void check_inputs(std::span<const std::shared_ptr<const CameraModel>> models, std::span<const ImageSize> sizes,
                  std::span<const ParticleSnapshot> snapshots, const VolumeBounds& bounds,
                  const SelfCalibrationOptions& options) {
  if (const std::string problem = options.validate(); !problem.empty())
    throw bad_input("self-calibration options: " + problem);
  if (const std::string problem = bounds.validate(); !problem.empty())
    throw bad_input("self-calibration volume: " + problem);
  if (models.size() < 3)
    throw bad_input(fmt::format("self-calibration needs at least 3 cameras to tell particles from ghosts; {} given",
                                models.size()));
  if (sizes.size() != models.size())
    throw bad_input(fmt::format("self-calibration: {} camera models but {} image sizes", models.size(), sizes.size()));
  for (std::size_t c = 0; c < models.size(); ++c)
    if (!models[c]) throw bad_input(fmt::format("self-calibration: {} has no camera model", camera_name(options, c)));
  if (snapshots.empty())
    throw bad_input("self-calibration needs particle images: no snapshot (set and exposure) given");
  for (std::size_t s = 0; s < snapshots.size(); ++s) {
    if (snapshots[s].images.size() != models.size())
      throw bad_input(fmt::format("self-calibration: snapshot {} has {} images but there are {} cameras", s,
                                  snapshots[s].images.size(), models.size()));
    for (std::size_t c = 0; c < models.size(); ++c) {
      const Image& im = snapshots[s].images[c];
      if (im.width() != sizes[c].width || im.height() != sizes[c].height)
        throw bad_input(fmt::format("self-calibration: {} image of snapshot {} is {} x {} but the camera is "
                                    "calibrated for {} x {}",
                                    camera_name(options, c), s, im.width(), im.height(), sizes[c].width,
                                    sizes[c].height));
    }
  }
}

selfcal::ModelList raw(const std::vector<std::shared_ptr<const CameraModel>>& models) {
  selfcal::ModelList out;
  for (const auto& m : models) out.push_back(m.get());
  return out;
}

}  // namespace

std::string VolumeBounds::validate() const {
  const auto finite = [](const Vec3d& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!finite(min) || !finite(max)) return "the bounds are not finite";
  if (!(max.x > min.x && max.y > min.y && max.z > min.z))
    return fmt::format("the bounds x [{}, {}], y [{}, {}], z [{}, {}] mm are empty: each max must exceed its min",
                       min.x, max.x, min.y, max.y, min.z, max.z);
  return {};
}

std::string SelfCalibrationOptions::validate() const {
  if (subvolumes_x < 1 || subvolumes_y < 1 || subvolumes_z < 1 || subvolumes_x > 50 || subvolumes_y > 50 ||
      subvolumes_z > 50)
    return fmt::format("sub-volumes {} x {} x {}: each must be 1 to 50", subvolumes_x, subvolumes_y, subvolumes_z);
  if (!(search_radius_px > 0 && search_radius_px <= 20))
    return fmt::format("search radius {} px must be in (0, 20]", search_radius_px);
  if (!(min_search_radius_px > 0 && min_search_radius_px <= search_radius_px))
    return fmt::format("minimum search radius {} px must be in (0, search radius {}]", min_search_radius_px,
                       search_radius_px);
  if (!(tolerance_px > 0)) return fmt::format("tolerance {} px must be > 0", tolerance_px);
  if (max_iterations < 0) return fmt::format("max iterations {} must be >= 0", max_iterations);
  if (!(peak_threshold >= 0)) return fmt::format("peak threshold {} must be >= 0 (0: automatic)", peak_threshold);
  if (!(peak_window_px > 0)) return fmt::format("peak window {} px must be > 0", peak_window_px);
  if (min_matches_per_subvolume < 1)
    return fmt::format("minimum matches per sub-volume {} must be >= 1", min_matches_per_subvolume);
  return {};
}

double SelfCalibrationPass::largest_mean_px() const {
  double m = 0;
  for (const auto& c : cameras) m = std::max(m, c.volume.mean_px);
  return m;
}

SelfCalibrationResult self_calibrate(std::span<const std::shared_ptr<const CameraModel>> models,
                                     std::span<const ImageSize> image_sizes,
                                     std::span<const ParticleSnapshot> snapshots, const VolumeBounds& bounds,
                                     const SelfCalibrationOptions& options) {
  check_inputs(models, image_sizes, snapshots, bounds, options);
  const std::size_t cameras = models.size();
  SelfCalibrationResult result;
  result.models.assign(models.begin(), models.end());
  result.refits.resize(cameras);
  result.peaks.assign(cameras, 0);

  // Peaks do not depend on the models: detect them once.
  std::vector<std::vector<PeakIndex>> peaks(snapshots.size());
  for (std::size_t s = 0; s < snapshots.size(); ++s)
    for (std::size_t c = 0; c < cameras; ++c) {
      peaks[s].emplace_back(selfcal::detect_peaks(snapshots[s].images[c], options.peak_threshold),
                            image_sizes[c].width, image_sizes[c].height);
      result.peaks[c] += peaks[s].back().peaks().size();
    }
  for (std::size_t c = 0; c < cameras; ++c)
    if (result.peaks[c] == 0)
      throw bad_input(fmt::format("self-calibration: no particle images found in {}'s images; check the images and "
                                  "the peak threshold",
                                  camera_name(options, c)));

  const selfcal::SubvolumeGrid grid{bounds, options.subvolumes_x, options.subvolumes_y, options.subvolumes_z};
  result.z_min_layer_mm = grid.layer_z(0);
  result.z_max_layer_mm = grid.layer_z(grid.nz - 1);
  const selfcal::ModelList initial = raw(result.models);
  double radius = options.search_radius_px;
  for (;;) {
    const selfcal::ModelList current = raw(result.models);
    selfcal::Matches matches;
    for (const auto& snapshot_peaks : peaks) selfcal::find_matches(current, snapshot_peaks, bounds, radius, matches);
    const selfcal::DisparityMaps maps = selfcal::measure_disparities(matches, grid, radius, options);

    SelfCalibrationPass pass;
    pass.search_radius_px = radius;
    pass.matches = matches.size();
    pass.unique_matches = matches.unique;
    for (std::size_t c = 0; c < cameras; ++c) pass.cameras.push_back(selfcal::summarise(*current[c], maps[c], grid));
    result.passes.push_back(pass);
    for (std::size_t c = 0; c < cameras; ++c)
      if (pass.cameras[c].volume.subvolumes < 4)
        throw bad_input(fmt::format(
            "self-calibration: too few particles to measure {}'s disparities: {} matched candidate particles in "
            "total, {} of {} sub-volumes with at least {} near their disparity peak (4 needed), {} peaks detected; "
            "use more sets, a higher particle density, fewer sub-volumes or a larger search radius",
            camera_name(options, c), matches.size(), pass.cameras[c].volume.subvolumes, grid.count(),
            options.min_matches_per_subvolume, result.peaks[c]));

    if (pass.largest_mean_px() < options.tolerance_px) {
      result.converged = true;
      break;
    }
    if (result.corrections >= options.max_iterations) break;

    const selfcal::DisparityMaps corrections = selfcal::gauge_corrections(initial, current, maps, options.sparse_gauge);
    std::vector<std::shared_ptr<const CameraModel>> corrected(cameras);
    for (std::size_t c = 0; c < cameras; ++c) {
      const selfcal::CorrectionField field(corrections[c], bounds, camera_name(options, c));
      FitReport report;
      corrected[c] = selfcal::refit_with_offsets(
          *current[c], image_sizes[c], bounds,
          [&field](const Vec3d& world, const Vec2d&) {
            const Vec2d d = field.at(world);
            return Vec2d{-d.x, -d.y};
          },
          camera_name(options, c), report);
      result.refits[c] = report;
    }
    result.models = std::move(corrected);
    ++result.corrections;
    radius = std::max(options.min_search_radius_px, radius / 2);
  }

  if (!result.converged && options.require_convergence) {
    std::string cams;
    for (std::size_t c = 0; c < cameras; ++c) {
      const double mean = result.after().cameras[c].volume.mean_px;
      if (mean >= options.tolerance_px)
        cams += fmt::format("{}{}: mean disparity {:.3f} px", cams.empty() ? "" : "; ", camera_name(options, c), mean);
    }
    throw runtime_error(fmt::format("self-calibration did not converge in {} corrections (tolerance {} px): {}; check "
                                    "the initial calibration, raise the search radius or the number of iterations",
                                    result.corrections, options.tolerance_px, cams));
  }
  return result;
}

std::unique_ptr<CameraModel> misaligned_camera(const CameraModel& model, ImageSize image_size,
                                               const VolumeBounds& bounds, Vec2d shift_px, double rotation_deg,
                                               FitReport& report) {
  if (const std::string problem = bounds.validate(); !problem.empty()) throw bad_input("volume: " + problem);
  const double a = rotation_deg * M_PI / 180.0, ca = std::cos(a), sa = std::sin(a);
  const Vec2d centre{(image_size.width - 1) * 0.5, (image_size.height - 1) * 0.5};
  return selfcal::refit_with_offsets(
      model, image_size, bounds,
      [&](const Vec3d&, const Vec2d& p) {
        const double x = p.x - centre.x, y = p.y - centre.y;
        return Vec2d{centre.x + ca * x - sa * y + shift_px.x - p.x, centre.y + sa * x + ca * y + shift_px.y - p.y};
      },
      "misaligned camera", report);
}

ProjectionDifference projection_difference(const CameraModel& a, const CameraModel& b,
                                           std::span<const Vec3d> points) {
  ProjectionDifference d;
  double sum = 0;
  for (const Vec3d& p : points) {
    const Vec2d pa = a.project(p), pb = b.project(p);
    const double e = std::hypot(pa.x - pb.x, pa.y - pb.y);
    sum += e;
    d.max_px = std::max(d.max_px, e);
  }
  d.points = points.size();
  if (d.points > 0) d.mean_px = sum / static_cast<double>(d.points);
  return d;
}

}  // namespace tomorig::calibration
