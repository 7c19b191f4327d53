#include "tomorig/pipeline/session_selfcal.h"

#include <algorithm>
#include <memory>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::pipeline {
namespace {

calibration::VolumeBounds bounds_of(const SessionSelfcalOptions& options, const SessionDescription& session) {
  if (options.volume) return *options.volume;
  const VoxelGrid g = options.grid.empty() ? grid_from_session(session) : parse_grid(options.grid);
  const double h = 0.5 * g.voxel_size;
  const Vec3d last = g.centre_of(g.nx - 1, g.ny - 1, g.nz - 1);
  return {{g.origin.x - h, g.origin.y - h, g.origin.z - h}, {last.x + h, last.y + h, last.z + h}};
}

std::vector<std::uint64_t> sets_of(const SessionSelfcalOptions& options, const storage::SessionReader& session) {
  std::vector<std::uint64_t> sets = options.sets;
  if (sets.empty())
    for (std::uint64_t k = 0; k < std::min(session.set_count(), options.default_sets); ++k) sets.push_back(k);
  if (sets.empty())
    throw bad_input(fmt::format("session '{}' has no sets to self-calibrate with", session.path().string()));
  for (const std::uint64_t k : sets)
    if (k >= session.set_count())
      throw bad_input(fmt::format("--sets: set {} is out of range: session '{}' has {} sets", k,
                                  session.path().string(), session.set_count()));
  return sets;
}

// The corrected models as calibration records: a refitted camera keeps its new fit report, an
// untouched one the report of the input file (when it came from one).
std::vector<calibration::CameraCalibration> calibration_of(const calibration::SelfCalibrationResult& r,
                                                           const std::vector<calibration::ImageSize>& sizes,
                                                           const std::vector<std::string>& names,
                                                           const std::string& calib) {
  std::vector<calibration::CameraCalibration> original;
  if (!calib.empty() && calib != "truth") original = calibration::load_calibration(calib);
  std::vector<calibration::CameraCalibration> out;
  for (std::size_t c = 0; c < r.models.size(); ++c) {
    calibration::CameraCalibration cal;
    cal.id = static_cast<int>(c);
    cal.image_size = sizes[c];
    cal.model = r.models[c];
    if (r.refits[c]) {
      cal.report = *r.refits[c];
    } else {
      for (const auto& o : original)
        if (o.id == cal.id) cal.report = o.report;
      cal.report.model = cal.model->model_name();
    }
    cal.report.camera = names[c];
    out.push_back(cal);
  }
  return out;
}

}  // namespace

SessionSelfcalReport selfcal_session(const std::filesystem::path& path, SessionSelfcalOptions options,
                                     const std::function<void(const std::string&)>& notice) {
  const storage::SessionReader session(path);
  const SessionDescription description = describe_session(session);
  SessionSelfcalReport report;
  const SessionCameras cameras = session_cameras(description, options.calib);
  report.cameras_source = cameras.source;
  report.bounds = bounds_of(options, description);
  if (const std::string problem = report.bounds.validate(); !problem.empty()) throw bad_input("--volume: " + problem);
  report.sets = sets_of(options, session);

  std::vector<calibration::ImageSize> sizes;
  calibration::SelfCalibrationOptions& selfcal = options.selfcal;
  selfcal.camera_names.clear();
  for (std::size_t c = 0; c < description.cameras.size(); ++c) {
    const auto& cam = description.cameras[c];
    sizes.push_back({cam.width, cam.height});
    selfcal.camera_names.push_back(fmt::format("camera {} ({})", c, cam.id));
  }
  selfcal.min_search_radius_px = std::min(selfcal.min_search_radius_px, selfcal.search_radius_px);
  selfcal.require_convergence = false;  // the report is made either way; the caller decides
  if (const std::string problem = selfcal.validate(); !problem.empty()) throw bad_input(problem);
  report.camera_names = selfcal.camera_names;

  std::vector<std::shared_ptr<const calibration::CameraModel>> models = cameras.models;
  if (options.perturb) {
    const auto& p = *options.perturb;
    if (p.camera >= models.size())
      throw bad_input(fmt::format("--perturb takes CAMERA,DU_PX,DV_PX,ROTATION_DEG with CAMERA one of 0 to {}",
                                  models.size() - 1));
    calibration::FitReport ignored;
    models[p.camera] = calibration::misaligned_camera(*models[p.camera], sizes[p.camera], report.bounds,
                                                      {p.du_px, p.dv_px}, p.rotation_deg, ignored);
  }

  std::vector<calibration::ParticleSnapshot> snapshots;
  std::vector<Vec3d> true_particles;
  for (const std::uint64_t k : report.sets) {
    const FrameSet set = session.read_set(k);
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      if ((e == Exposure::A && !options.use_a) || (e == Exposure::B && !options.use_b)) continue;
      calibration::ParticleSnapshot snapshot;
      for (const CameraFrames& c : set.cameras) snapshot.images.push_back(c[e].image);
      bool complete = true;
      for (const Image& im : snapshot.images) complete = complete && !im.empty();
      if (!complete) {
        if (notice) notice(fmt::format("warning: set {} exposure {} misses a frame; skipped", k, e == Exposure::A ? "A" : "B"));
        continue;
      }
      snapshots.push_back(std::move(snapshot));
      if (description.truth && session.has_truth_set(k)) {
        const storage::TruthSet t = session.truth_set(k);
        const auto& particles = e == Exposure::A ? t.particles_a : t.particles_b;
        true_particles.insert(true_particles.end(), particles.begin(), particles.end());
      }
    }
  }
  report.snapshots = snapshots.size();
  if (notice)
    notice(fmt::format("self-calibrating {} cameras of '{}' with {} snapshots (sets x exposures)...", models.size(),
                     path.string(), snapshots.size()));
  report.result = calibration::self_calibrate(models, sizes, snapshots, report.bounds, selfcal);
  const calibration::SelfCalibrationResult& r = report.result;

  report.truth_before.assign(models.size(), std::nullopt);
  report.truth_after.assign(models.size(), std::nullopt);
  if (description.truth && !true_particles.empty()) {
    const SessionCameras truth = truth_cameras(description);
    for (std::size_t c = 0; c < models.size(); ++c) {
      report.truth_before[c] = calibration::projection_difference(*models[c], *truth.models[c], true_particles).mean_px;
      report.truth_after[c] = calibration::projection_difference(*r.models[c], *truth.models[c], true_particles).mean_px;
    }
  }
  for (std::size_t c = 0; c < models.size(); ++c)
    if (r.after().cameras[c].volume.mean_px >= selfcal.tolerance_px)
      report.not_converged += fmt::format("{}{}: mean disparity {:.3f} px", report.not_converged.empty() ? "" : "; ",
                                          selfcal.camera_names[c], r.after().cameras[c].volume.mean_px);
  report.calibration = calibration_of(r, sizes, selfcal.camera_names, options.calib);
  return report;
}

}  // namespace tomorig::pipeline
