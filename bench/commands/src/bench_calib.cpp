// tomorig bench calib --case calib-thesis: renders the chessboard case, detects the corners,
// fits each camera model with and without traverse (stage) correction, and judges the fits and
// the recovered plane offsets against the simulator's truth (thesis Tables 6.3 / 6.4).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "bench_common.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/processing/calibration/traverse_correction.h"
#include "tomorig/simulators/calibration_target.h"

namespace tomorig::bench {
namespace {

struct BenchCalibArgs {
  std::string case_name = "calib-thesis";
  bool reduced = false;
  std::uint64_t seed = 1;
  std::vector<std::string> models{"pinhole", "rational2"};
  double distortion_px = sim::CalibTargetOptions{}.distortion_corner_px;
  std::string json_out;
};

// Largest distance (um) between estimated and true offsets over the planes, both zero-mean.
double offset_error_um(const std::vector<Vec3d>& estimate, const std::vector<Vec3d>& truth) {
  double worst = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) worst = std::max(worst, (estimate[k] - truth[k]).norm() * 1e3);
  return worst;
}

nlohmann::json um3(const Vec3d& v) { return {v.x * 1e3, v.y * 1e3, v.z * 1e3}; }

void run(const BenchCalibArgs& args) {
  if (args.case_name != "calib-thesis")
    throw bad_input(fmt::format("bench calib: --case '{}' is unknown: use calib-thesis", args.case_name));
  for (const std::string& m : args.models) {
    const auto& names = calibration::camera_model_names();
    if (std::find(names.begin(), names.end(), m) == names.end())
      throw bad_input(fmt::format("bench calib: --models: '{}' is not a camera model", m));
  }
  sim::CalibTargetOptions opt;
  opt.reduced = args.reduced;
  opt.seed = args.seed;
  opt.distortion_corner_px = args.distortion_px;
  const sim::CalibTargetCase c = sim::make_calib_thesis_case(opt);
  const std::size_t cams = c.cameras.size(), planes = c.planes.size();

  // Truth offsets in the correction's gauge (traverse_correction.h).
  std::vector<Vec3d> truth;
  std::vector<double> plane_z;
  for (const sim::TargetPlane& p : c.planes) truth.push_back(p.offset_mm), plane_z.push_back(p.z_nominal_mm);
  calibration::remove_gauge(truth, plane_z);
  const std::vector<Vec3d> zero(planes, Vec3d{0, 0, 0});

  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::vector<calibration::PointCorrespondence>> points(cams);
  std::vector<calibration::ImageSize> sizes;
  nlohmann::json detection = nlohmann::json::array();
  for (std::size_t cam = 0; cam < cams; ++cam) {
    sizes.push_back({c.cameras[cam].width, c.cameras[cam].height});
    double sum = 0, worst = 0;
    int n = 0, warnings = 0;
    for (std::size_t k = 0; k < planes; ++k) {
      const Image img = sim::render_target_view(c, cam, k);
      const calibration::TargetDetection d = calibration::detect_chessboard(
          img, c.board, c.planes[k].z_nominal_mm, fmt::format("{}, plane z = {} mm", c.cameras[cam].id, c.planes[k].z_nominal_mm));
      warnings += static_cast<int>(d.warnings.size());
      for (const calibration::PointCorrespondence& p : d.points) {
        const int i = static_cast<int>(std::lround(p.world.x / c.board.square_mm));
        const int j = static_cast<int>(std::lround(p.world.y / c.board.square_mm));
        const Vec2d t = c.corner_pixel(cam, i, j, k);
        const double e = std::hypot(p.pixel.x - t.x, p.pixel.y - t.y);
        sum += e, worst = std::max(worst, e), ++n;
        points[cam].push_back(p);
      }
    }
    detection.push_back({{"camera", cam + 1}, {"corners", n}, {"warnings", warnings},
                         {"corner_error_mean_px", json_number(n ? sum / n : NAN)}, {"corner_error_max_px", worst}});
  }
  const double detect_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  nlohmann::json results = nlohmann::json::array();
  nlohmann::json offsets_json = nlohmann::json::array();
  for (const std::string& model : args.models) {
    // Without correction: each camera on its own, nominal plane positions.
    for (std::size_t cam = 0; cam < cams; ++cam) {
      calibration::FitOptions fo;
      fo.camera = c.cameras[cam].id;
      calibration::FitReport report;
      calibration::fit_camera_model(model, points[cam], sizes[cam], fo, report);
      results.push_back({{"model", model}, {"stage_correction", false}, {"camera", cam + 1},
                         {"forward_px", report.forward_mean_px}, {"forward_max_px", report.forward_max_px},
                         {"reverse_um", report.reverse_mean_um},
                         {"stage_offset_error_um", offset_error_um(zero, truth)}});
    }
    calibration::TraverseCorrectionOptions to;
    to.final_model = model;
    for (const auto& cam : c.cameras) to.camera_names.push_back(cam.id);
    const calibration::TraverseCorrectionResult r = calibration::correct_traverse(points, sizes, to);
    for (std::size_t cam = 0; cam < cams; ++cam)
      results.push_back({{"model", model}, {"stage_correction", true}, {"camera", cam + 1},
                         {"forward_px", r.reports[cam].forward_mean_px}, {"forward_max_px", r.reports[cam].forward_max_px},
                         {"reverse_um", r.reports[cam].reverse_mean_um},
                         {"stage_offset_error_um", offset_error_um(r.offsets_mm, truth)},
                         {"single_camera_offset_error_um", offset_error_um(r.per_camera_offsets_mm[cam], truth)},
                         {"cycles", r.cycles}, {"converged", r.converged}});
    if (offsets_json.empty())
      for (std::size_t k = 0; k < planes; ++k) {
        nlohmann::json per_camera = nlohmann::json::array();
        for (std::size_t cam = 0; cam < cams; ++cam) per_camera.push_back(um3(r.per_camera_offsets_mm[cam][k]));
        offsets_json.push_back({{"z_nominal_mm", c.planes[k].z_nominal_mm}, {"truth_um", um3(truth[k])},
                                {"estimate_um", um3(r.offsets_mm[k])}, {"per_camera_um", per_camera}});
      }
  }
  const nlohmann::json out = {
      {"case", args.case_name},
      {"variant", args.reduced ? "reduced 640 x 540" : "full 2560 x 2160"},
      {"seed", args.seed},
      {"distortion_corner_px", args.distortion_px},
      {"offset_gauge", "zero mean; no linear trend over z in x and z (estimate and truth; traverse_correction.h)"},
      {"detection", detection},
      {"render_and_detect_seconds", detect_seconds},
      {"results", results},
      {"plane_offsets", offsets_json},
      {"machine", machine_json()}};
  write_json(out, args.json_out);
}

}  // namespace

void add_bench_calib_command(CLI::App& bench) {
  auto args = std::make_shared<BenchCalibArgs>();
  CLI::App* cmd = bench.add_subcommand(
      "calib", "Calibrate the simulated chessboard case with each model, with and without stage correction; "
               "judge against the truth");
  cmd->add_option("--case", args->case_name, "Simulated case: calib-thesis")->capture_default_str();
  cmd->add_flag("--reduced", args->reduced, "Render the reduced 640 x 540 variant");
  cmd->add_option("--seed", args->seed, "Random seed (stage errors, noise)")->capture_default_str();
  cmd->add_option("--models", args->models, "Camera models, e.g. pinhole,rational2")->delimiter(',')->capture_default_str();
  cmd->add_option("--distortion-px", args->distortion_px, "Radial lens distortion at the image corner (full-size px)")
      ->capture_default_str();
  cmd->add_option("--json", args->json_out, "Write the JSON to FILE (.json); --json alone, '-' or none: stdout")
      ->expected(0, 1);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::bench
