// tomorig selfcal: volume self-calibration (thesis Sect. 2.2, Wieneke 2008) of a calibration
// with the particle images of a session; prints the disparities before and after (Table 5.4)
// and writes the corrected calibration file.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/self_calibration.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {

using pipeline::SessionCameras;
using pipeline::grid_from_session;
using pipeline::parse_grid;
using pipeline::session_cameras;
using pipeline::truth_cameras;

namespace {

constexpr std::uint64_t kDefaultSetLimit = 10;

struct SelfcalArgs {
  std::string session;
  std::string calib;
  std::string out;
  std::string sets;
  std::string exposure = "both";
  std::string grid;
  std::string volume;
  std::vector<int> subvolumes{5, 5, 3};
  double search_radius_px = 2.0;
  double min_search_radius_px = 0.75;
  double tolerance_px = 0.05;
  int max_iterations = 6;
  double peak_threshold = 0;
  int min_matches = 10;
  std::string gauge = "sparse";
  std::vector<double> perturb;  // camera, du, dv, rotation deg
  bool overwrite = false;
  bool json = false;
};

std::vector<double> parse_numbers(const std::string& text, const std::string& flag, const std::string& form) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    double v = 0;
    const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (ec != std::errc() || end != item.data() + item.size() || !std::isfinite(v))
      throw bad_input(fmt::format("{} '{}' is not valid: expected {}", flag, text, form));
    values.push_back(v);
  }
  return values;
}

// "0,2,5-7" -> {0, 2, 5, 6, 7}; empty: the first kDefaultSetLimit sets.
std::vector<std::uint64_t> parse_sets(const std::string& text, std::uint64_t set_count, const std::string& session) {
  std::vector<std::uint64_t> sets;
  if (text.empty()) {
    for (std::uint64_t k = 0; k < std::min(set_count, kDefaultSetLimit); ++k) sets.push_back(k);
  } else {
    std::stringstream in(text);
    std::string item;
    const auto fail = [&] {
      throw bad_input(fmt::format("--sets '{}' is not valid: expected set indices and ranges such as 0,2,5-7", text));
    };
    const auto number = [&](const std::string& s) {
      std::uint64_t v = 0;
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (s.empty() || ec != std::errc() || end != s.data() + s.size()) fail();
      return v;
    };
    while (std::getline(in, item, ',')) {
      const auto dash = item.find('-');
      const std::uint64_t first = number(item.substr(0, dash));
      const std::uint64_t last = dash == std::string::npos ? first : number(item.substr(dash + 1));
      if (last < first) fail();
      for (std::uint64_t k = first; k <= last; ++k) sets.push_back(k);
    }
  }
  if (sets.empty()) throw bad_input(fmt::format("session '{}' has no sets to self-calibrate with", session));
  for (const std::uint64_t k : sets)
    if (k >= set_count)
      throw bad_input(fmt::format("--sets: set {} is out of range: session '{}' has {} sets", k, session, set_count));
  return sets;
}

calibration::VolumeBounds volume_bounds(const SelfcalArgs& args, const pipeline::SessionDescription& session) {
  if (!args.volume.empty()) {
    const auto v = parse_numbers(args.volume, "--volume", "xmin,ymin,zmin,xmax,ymax,zmax in mm");
    if (v.size() != 6)
      throw bad_input(fmt::format("--volume '{}' is not valid: expected six numbers xmin,ymin,zmin,xmax,ymax,zmax (mm)",
                                  args.volume));
    return {{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  }
  const VoxelGrid g = args.grid.empty() ? grid_from_session(session) : parse_grid(args.grid);
  const double h = 0.5 * g.voxel_size;
  const Vec3d last = g.centre_of(g.nx - 1, g.ny - 1, g.nz - 1);
  return {{g.origin.x - h, g.origin.y - h, g.origin.z - h}, {last.x + h, last.y + h, last.z + h}};
}

nlohmann::json figures_json(const calibration::DisparityFigures& f) {
  return {{"mean_px", f.mean_px}, {"max_px", f.max_px}, {"mean_um", f.mean_um}, {"subvolumes", f.subvolumes}};
}

nlohmann::json camera_json(const calibration::CameraDisparity& d) {
  return {{"volume", figures_json(d.volume)},
          {"z_min_layer", figures_json(d.z_min_layer)},
          {"z_max_layer", figures_json(d.z_max_layer)}};
}

void print_table(const calibration::SelfCalibrationResult& r, const std::vector<std::optional<double>>& truth_before,
                 const std::vector<std::optional<double>>& truth_after) {
  fmt::print("pass  radius px  candidates  unique\n");
  for (std::size_t p = 0; p < r.passes.size(); ++p)
    fmt::print("{:>4}  {:>9.2f}  {:>10}  {:>6}\n", p, r.passes[p].search_radius_px, r.passes[p].matches,
               r.passes[p].unique_matches);
  fmt::print("\nmean disparity magnitude per camera (Table 5.4): fwd. px, rev. um\n");
  fmt::print("camera  sub-volumes             before fwd  rev um   after fwd  rev um   max after\n");
  for (std::size_t c = 0; c < r.models.size(); ++c) {
    const auto& b = r.before().cameras[c];
    const auto& a = r.after().cameras[c];
    const auto row = [&](const std::string& where, const calibration::DisparityFigures& fb,
                         const calibration::DisparityFigures& fa) {
      fmt::print("{:>6}  {:<22}  {:>9.3f}  {:>6.2f}  {:>10.3f}  {:>6.2f}  {:>9.3f}\n", c, where, fb.mean_px, fb.mean_um,
                 fa.mean_px, fa.mean_um, fa.max_px);
    };
    row("all", b.volume, a.volume);
    row(fmt::format("z-min layer z={:.2f}", r.z_min_layer_mm), b.z_min_layer, a.z_min_layer);
    row(fmt::format("z-max layer z={:.2f}", r.z_max_layer_mm), b.z_max_layer, a.z_max_layer);
  }
  if (truth_before.front()) {
    fmt::print("\nagainst the truth (mean |model - true camera| projection of the true particles, px)\n");
    fmt::print("camera  before   after\n");
    for (std::size_t c = 0; c < r.models.size(); ++c)
      fmt::print("{:>6}  {:>6.3f}  {:>6.3f}\n", c, *truth_before[c], *truth_after[c]);
  }
}

void run(const SelfcalArgs& args) {
  if (std::filesystem::exists(args.out) && !args.overwrite)
    throw bad_input(fmt::format("'{}' exists; give --overwrite to replace it", args.out));
  if (args.subvolumes.size() != 3)
    throw bad_input("--subvolumes takes three whole numbers nx,ny,nz, e.g. 5,5,3");
  const storage::SessionReader session(args.session);
  const pipeline::SessionDescription description = pipeline::describe_session(session);
  const SessionCameras cameras = session_cameras(description, args.calib);
  const calibration::VolumeBounds bounds = volume_bounds(args, description);
  if (const std::string problem = bounds.validate(); !problem.empty()) throw bad_input("--volume: " + problem);
  const std::vector<std::uint64_t> sets = parse_sets(args.sets, session.set_count(), args.session);

  std::vector<calibration::ImageSize> sizes;
  calibration::SelfCalibrationOptions options;
  for (std::size_t c = 0; c < session.info().cameras.size(); ++c) {
    const auto& cam = session.info().cameras[c];
    sizes.push_back({cam.width, cam.height});
    options.camera_names.push_back(fmt::format("camera {} ({})", c, cam.id));
  }
  options.subvolumes_x = args.subvolumes[0];
  options.subvolumes_y = args.subvolumes[1];
  options.subvolumes_z = args.subvolumes[2];
  options.search_radius_px = args.search_radius_px;
  options.min_search_radius_px = std::min(args.min_search_radius_px, args.search_radius_px);
  options.tolerance_px = args.tolerance_px;
  options.max_iterations = args.max_iterations;
  options.peak_threshold = args.peak_threshold;
  options.min_matches_per_subvolume = args.min_matches;
  options.sparse_gauge = args.gauge == "sparse";
  options.require_convergence = false;  // the table is printed either way; the error follows it
  if (const std::string problem = options.validate(); !problem.empty()) throw bad_input(problem);

  std::vector<std::shared_ptr<const calibration::CameraModel>> models = cameras.models;
  if (!args.perturb.empty()) {
    if (args.perturb.size() != 4 || args.perturb[0] < 0 || args.perturb[0] >= static_cast<double>(models.size()) ||
        args.perturb[0] != std::floor(args.perturb[0]))
      throw bad_input(fmt::format("--perturb takes CAMERA,DU_PX,DV_PX,ROTATION_DEG with CAMERA one of 0 to {}",
                                  models.size() - 1));
    const auto c = static_cast<std::size_t>(args.perturb[0]);
    calibration::FitReport report;
    models[c] = calibration::misaligned_camera(*models[c], sizes[c], bounds, {args.perturb[1], args.perturb[2]},
                                               args.perturb[3], report);
  }

  std::vector<calibration::ParticleSnapshot> snapshots;
  std::vector<Vec3d> true_particles;
  const bool truth = session.has_truth();
  const bool use_a = args.exposure != "b", use_b = args.exposure != "a";
  for (const std::uint64_t k : sets) {
    const FrameSet set = session.read_set(k);
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      if ((e == Exposure::A && !use_a) || (e == Exposure::B && !use_b)) continue;
      calibration::ParticleSnapshot snapshot;
      for (const CameraFrames& c : set.cameras) snapshot.images.push_back(c[e].image);
      bool complete = true;
      for (const Image& im : snapshot.images) complete = complete && !im.empty();
      if (!complete) {
        fmt::print(stderr, "warning: set {} exposure {} misses a frame; skipped\n", k, e == Exposure::A ? "A" : "B");
        continue;
      }
      snapshots.push_back(std::move(snapshot));
      if (truth && session.has_truth_set(k)) {
        const storage::TruthSet t = session.truth_set(k);
        const auto& p = e == Exposure::A ? t.particles_a : t.particles_b;
        true_particles.insert(true_particles.end(), p.begin(), p.end());
      }
    }
  }
  fmt::print(stderr, "self-calibrating {} cameras of '{}' with {} snapshots (sets x exposures)...\n", models.size(),
             args.session, snapshots.size());
  const calibration::SelfCalibrationResult r = calibration::self_calibrate(models, sizes, snapshots, bounds, options);

  std::vector<std::optional<double>> truth_before(models.size()), truth_after(models.size());
  if (truth && !true_particles.empty()) {
    const SessionCameras true_cameras = truth_cameras(description);
    for (std::size_t c = 0; c < models.size(); ++c) {
      truth_before[c] = calibration::projection_difference(*models[c], *true_cameras.models[c], true_particles).mean_px;
      truth_after[c] = calibration::projection_difference(*r.models[c], *true_cameras.models[c], true_particles).mean_px;
    }
  }

  // Not converged: report, then fail without writing a calibration that is not good enough.
  std::string failed;
  for (std::size_t c = 0; c < models.size(); ++c)
    if (r.after().cameras[c].volume.mean_px >= options.tolerance_px)
      failed += fmt::format("{}{}: mean disparity {:.3f} px", failed.empty() ? "" : "; ", options.camera_names[c],
                            r.after().cameras[c].volume.mean_px);

  if (r.converged) {
    std::vector<calibration::CameraCalibration> out;
    std::vector<calibration::CameraCalibration> original;
    if (!args.calib.empty() && args.calib != "truth") original = calibration::load_calibration(args.calib);
    for (std::size_t c = 0; c < models.size(); ++c) {
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
      cal.report.camera = options.camera_names[c];
      out.push_back(cal);
    }
    calibration::save_calibration(args.out, out);
  }

  if (args.json) {
    nlohmann::json cams = nlohmann::json::array();
    for (std::size_t c = 0; c < models.size(); ++c) {
      nlohmann::json j = {{"camera", c},
                          {"model", r.models[c]->model_name()},
                          {"peaks", r.peaks[c]},
                          {"before", camera_json(r.before().cameras[c])},
                          {"after", camera_json(r.after().cameras[c])}};
      if (truth_before[c]) {
        j["truth_before_px"] = *truth_before[c];
        j["truth_after_px"] = *truth_after[c];
      }
      if (r.refits[c]) j["refit_forward_mean_px"] = r.refits[c]->forward_mean_px;
      cams.push_back(j);
    }
    nlohmann::json passes = nlohmann::json::array();
    for (const auto& p : r.passes)
      passes.push_back({{"search_radius_px", p.search_radius_px}, {"matches", p.matches}, {"unique_matches", p.unique_matches}});
    fmt::print("{}\n", nlohmann::json{{"session", args.session},
                                      {"calibration", cameras.source},
                                      {"out", r.converged ? nlohmann::json(args.out) : nlohmann::json(nullptr)},
                                      {"sets", sets},
                                      {"snapshots", snapshots.size()},
                                      {"volume_mm", {{"min", {bounds.min.x, bounds.min.y, bounds.min.z}},
                                                     {"max", {bounds.max.x, bounds.max.y, bounds.max.z}}}},
                                      {"subvolumes", args.subvolumes},
                                      {"z_min_layer_mm", r.z_min_layer_mm},
                                      {"z_max_layer_mm", r.z_max_layer_mm},
                                      {"tolerance_px", options.tolerance_px},
                                      {"converged", r.converged},
                                      {"corrections", r.corrections},
                                      {"passes", passes},
                                      {"cameras", cams}}
                           .dump(2));
  } else {
    fmt::print("self-calibration of {} ({}), {} snapshot(s), volume x [{:.3f}, {:.3f}] y [{:.3f}, {:.3f}] z [{:.3f}, "
               "{:.3f}] mm, {} x {} x {} "
               "sub-volumes\n",
               args.session, cameras.source, snapshots.size(), bounds.min.x, bounds.max.x, bounds.min.y, bounds.max.y,
               bounds.min.z, bounds.max.z, args.subvolumes[0], args.subvolumes[1], args.subvolumes[2]);
    print_table(r, truth_before, truth_after);
    if (r.converged)
      fmt::print("\n{} after {} correction(s); wrote {}\n", r.corrections == 0 ? "already within tolerance" : "converged",
                 r.corrections, args.out);
  }
  if (!r.converged)
    throw runtime_error(fmt::format("self-calibration did not converge in {} corrections (tolerance {} px): {}; "
                                    "nothing written. Check the initial calibration, raise --search-radius or "
                                    "--max-iterations",
                                    r.corrections, options.tolerance_px, failed));
}

}  // namespace

void add_selfcal_command(CLI::App& root) {
  auto args = std::make_shared<SelfcalArgs>();
  CLI::App* cmd = root.add_subcommand(
      "selfcal", "Volume self-calibration: correct a calibration with the particle images of a session");
  cmd->add_option("--session", args->session, "Session file (.h5) with particle images")->required();
  cmd->add_option("--calib", args->calib,
                  "Calibration file (TOML) to correct, or 'truth' for a simulated session's exact cameras "
                  "(default: the truth if present, else the rig config's calibration file)");
  cmd->add_option("-o,--out", args->out, "Corrected calibration file to write (TOML)")->required();
  cmd->add_option("--sets", args->sets, "Sets to use, e.g. 0,2,5-7 (default: the first 10)");
  cmd->add_option("--exposure", args->exposure, "Exposures to use: a, b or both")
      ->check(CLI::IsMember({"a", "b", "both"}))
      ->capture_default_str();
  cmd->add_option("--grid", args->grid,
                  "Volume as a voxel grid nx,ny,nz,voxel_mm[,cx,cy,cz] (default: the rig config's [grid])");
  cmd->add_option("--volume", args->volume, "Volume bounds xmin,ymin,zmin,xmax,ymax,zmax in mm (instead of --grid)");
  cmd->add_option("--subvolumes", args->subvolumes, "Sub-volumes nx,ny,nz")->delimiter(',')->expected(3)->capture_default_str();
  cmd->add_option("--search-radius", args->search_radius_px,
                  "First search radius, px: must exceed the largest misalignment; halved each pass")
      ->capture_default_str();
  cmd->add_option("--min-search-radius", args->min_search_radius_px, "Smallest search radius, px")->capture_default_str();
  cmd->add_option("--tolerance", args->tolerance_px, "Converged when every camera's mean disparity is below this, px")
      ->capture_default_str();
  cmd->add_option("--max-iterations", args->max_iterations, "Corrections at most")->capture_default_str();
  cmd->add_option("--peak-threshold", args->peak_threshold,
                  "Particle peaks below this (counts) are ignored; 0: 10% of each image's 99.9th percentile")
      ->capture_default_str();
  cmd->add_option("--min-matches", args->min_matches, "Matches a sub-volume needs near its disparity peak")
      ->capture_default_str();
  cmd->add_option("--gauge", args->gauge,
                  "sparse: a misaligned camera takes its whole error (the world frame stays); plain: least-squares "
                  "disparities as measured")
      ->check(CLI::IsMember({"sparse", "plain"}))
      ->capture_default_str();
  cmd->add_option("--perturb", args->perturb,
                  "For tests: misalign camera CAMERA of the input first, CAMERA,DU_PX,DV_PX,ROTATION_DEG "
                  "(rotation about the image centre)")
      ->delimiter(',')
      ->expected(4);
  cmd->add_flag("--overwrite", args->overwrite, "Replace an existing output file");
  cmd->add_flag("--json", args->json, "Print the report as one JSON object");
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
