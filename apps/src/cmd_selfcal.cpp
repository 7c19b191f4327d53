// tomorig selfcal: volume self-calibration (thesis Sect. 2.2, Wieneke 2008) of a calibration
// with the particle images of a session (pipeline::selfcal_session); prints the disparities
// before and after (Table 5.4) and writes the corrected calibration file.
#include <algorithm>
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
#include "json_summary.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/set_selection.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_selfcal.h"

namespace tomorig::app {
namespace {

struct SelfcalArgs {
  std::string session;
  std::string out;
  std::string sets;
  std::string exposure = "both";
  std::string volume;
  std::vector<int> subvolumes{pipeline::SessionSelfcalOptions{}.selfcal.subvolumes_x,
                              pipeline::SessionSelfcalOptions{}.selfcal.subvolumes_y,
                              pipeline::SessionSelfcalOptions{}.selfcal.subvolumes_z};
  std::vector<double> perturb;  // camera, du, dv, rotation deg
  std::string gauge = "sparse";
  bool overwrite = false;
  JsonOutput json;
  pipeline::SessionSelfcalOptions options;  // calib, grid and the algorithm's settings bound directly
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

// The one set syntax (core/set_selection.h) against the session's sets; empty: none named (the
// library takes the first ten).
std::vector<std::uint64_t> parse_sets(const std::string& text, const std::string& session) {
  if (text.empty()) return {};
  const SetSelection selection = SetSelection::parse(text);
  return selection.indices(storage::SessionReader(session).set_count());
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

pipeline::SessionSelfcalOptions options_of(const SelfcalArgs& args) {
  pipeline::SessionSelfcalOptions o = args.options;
  if (args.subvolumes.size() != 3) throw bad_input("--subvolumes takes three whole numbers nx,ny,nz, e.g. 5,5,3");
  o.selfcal.subvolumes_x = args.subvolumes[0];
  o.selfcal.subvolumes_y = args.subvolumes[1];
  o.selfcal.subvolumes_z = args.subvolumes[2];
  o.selfcal.sparse_gauge = args.gauge == "sparse";
  o.sets = parse_sets(args.sets, args.session);
  o.use_a = args.exposure != "b";
  o.use_b = args.exposure != "a";
  if (!args.volume.empty()) {
    const auto v = parse_numbers(args.volume, "--volume", "xmin,ymin,zmin,xmax,ymax,zmax in mm");
    if (v.size() != 6)
      throw bad_input(fmt::format("--volume '{}' is not valid: expected six numbers xmin,ymin,zmin,xmax,ymax,zmax (mm)",
                                  args.volume));
    o.volume = calibration::VolumeBounds{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
  }
  if (!args.perturb.empty()) {
    const std::vector<double>& p = args.perturb;
    if (p.size() != 4 || p[0] < 0 || p[0] != std::floor(p[0]))
      throw bad_input("--perturb takes CAMERA,DU_PX,DV_PX,ROTATION_DEG with CAMERA a camera index");
    o.perturb = pipeline::SessionSelfcalOptions::Perturbation{static_cast<std::size_t>(p[0]), p[1], p[2], p[3]};
  }
  return o;
}

nlohmann::json report_json(const SelfcalArgs& args, const pipeline::SessionSelfcalReport& s) {
  const calibration::SelfCalibrationResult& r = s.result;
  nlohmann::json cams = nlohmann::json::array();
  for (std::size_t c = 0; c < r.models.size(); ++c) {
    nlohmann::json j = {{"camera", c},
                        {"model", r.models[c]->model_name()},
                        {"peaks", r.peaks[c]},
                        {"before", camera_json(r.before().cameras[c])},
                        {"after", camera_json(r.after().cameras[c])}};
    if (s.truth_before[c]) {
      j["truth_before_px"] = *s.truth_before[c];
      j["truth_after_px"] = *s.truth_after[c];
    }
    if (r.refits[c]) j["refit_forward_mean_px"] = r.refits[c]->forward_mean_px;
    cams.push_back(j);
  }
  nlohmann::json passes = nlohmann::json::array();
  for (const auto& p : r.passes)
    passes.push_back({{"search_radius_px", p.search_radius_px}, {"matches", p.matches}, {"unique_matches", p.unique_matches}});
  const calibration::VolumeBounds& b = s.bounds;
  return {{"session", args.session},
          {"calibration", s.cameras_source},
          {"out", r.converged ? nlohmann::json(args.out) : nlohmann::json(nullptr)},
          {"sets", s.sets},
          {"snapshots", s.snapshots},
          {"volume_mm", {{"min", {b.min.x, b.min.y, b.min.z}}, {"max", {b.max.x, b.max.y, b.max.z}}}},
          {"subvolumes", args.subvolumes},
          {"z_min_layer_mm", r.z_min_layer_mm},
          {"z_max_layer_mm", r.z_max_layer_mm},
          {"tolerance_px", args.options.selfcal.tolerance_px},
          {"converged", r.converged},
          {"corrections", r.corrections},
          {"passes", passes},
          {"cameras", cams}};
}

void run(const SelfcalArgs& args) {
  cli::require_session(args.session, "selfcal");
  if (std::filesystem::exists(args.out) && !args.overwrite)
    throw bad_input(fmt::format("'{}' exists; give --overwrite to replace it", args.out));
  const pipeline::SessionSelfcalReport s = pipeline::selfcal_session(
      args.session, options_of(args), [](const std::string& text) { fmt::print(stderr, "{}\n", text); });
  const calibration::SelfCalibrationResult& r = s.result;
  // Disparities near the first pass's search radius: larger ones were cut off by it, so the
  // "before" figures understate the misalignment and the correction may miss it (issue 18).
  if (!r.passes.empty())
    for (std::size_t c = 0; c < r.before().cameras.size(); ++c) {
      const double radius = r.before().search_radius_px, largest = r.before().cameras[c].volume.max_px;
      if (largest >= 0.75 * radius)
        fmt::print(stderr,
                   "warning: camera {}: sub-volume disparities before correction reach {:.2f} px, close to the "
                   "{:.2f} px search radius; larger misalignments are cut off by it and the 'before' figures "
                   "understate them: rerun with --search-radius {:.3g}\n",
                   c, largest, radius, std::min(20.0, 2 * radius));
    }
  // Not converged: report, then fail without writing a calibration that is not good enough.
  if (r.converged) calibration::save_calibration(args.out, s.calibration);
  nlohmann::json summary = json_summary("selfcal");
  summary.update(report_json(args, s));
  emit_json(args.json, summary);
  if (!args.json.to_stdout()) {
    const calibration::VolumeBounds& b = s.bounds;
    fmt::print("self-calibration of {} ({}), {} snapshot(s), volume x [{:.3f}, {:.3f}] y [{:.3f}, {:.3f}] z [{:.3f}, "
               "{:.3f}] mm, {} x {} x {} sub-volumes\n",
               args.session, s.cameras_source, s.snapshots, b.min.x, b.max.x, b.min.y, b.max.y, b.min.z, b.max.z,
               args.subvolumes[0], args.subvolumes[1], args.subvolumes[2]);
    print_table(r, s.truth_before, s.truth_after);
    if (r.converged)
      fmt::print("\n{} after {} correction(s); wrote {}\n", r.corrections == 0 ? "already within tolerance" : "converged",
                 r.corrections, args.out);
  }
  if (!r.converged)
    throw runtime_error(fmt::format("self-calibration did not converge in {} corrections (tolerance {} px): {}; "
                                    "nothing written. Check the initial calibration, raise --search-radius or "
                                    "--max-iterations",
                                    r.corrections, args.options.selfcal.tolerance_px, s.not_converged));
}

}  // namespace

void add_selfcal_command(CLI::App& root) {
  auto args = std::make_shared<SelfcalArgs>();
  CLI::App* cmd = root.add_subcommand(
      "selfcal", "Volume self-calibration: correct a calibration with the particle images of a session");
  cli::add_session_argument(*cmd, args->session, "Session file (.h5) with particle images");
  cmd->add_option("--calib", args->options.calib,
                  "Calibration file (TOML) to correct, or 'truth' for a simulated session's exact cameras "
                  "(default: the truth if present, else the rig config's calibration file)");
  cmd->add_option("-o,--out", args->out, "Corrected calibration file to write (TOML)")->required();
  cmd->add_option("--sets", args->sets, fmt::format("Sets to use: N (the first N), A:B (A to B-1) or a list such as 0,2,5-7 (default: the first {})", args->options.default_sets));
  cmd->add_option("--exposure", args->exposure, "Exposures to use: a, b or both")
      ->check(CLI::IsMember({"a", "b", "both"}))
      ->capture_default_str();
  cmd->add_option("--grid", args->options.grid,
                  "Volume as a voxel grid nx,ny,nz,voxel_mm[,cx,cy,cz] (default: the rig config's [grid])");
  cmd->add_option("--volume", args->volume, "Volume bounds xmin,ymin,zmin,xmax,ymax,zmax in mm (instead of --grid)");
  cmd->add_option("--subvolumes", args->subvolumes, "Sub-volumes nx,ny,nz")->delimiter(',')->expected(3)->capture_default_str();
  cmd->add_option("--search-radius", args->options.selfcal.search_radius_px,
                  "First search radius, px: must exceed the largest misalignment; halved each pass")
      ->capture_default_str();
  cmd->add_option("--min-search-radius", args->options.selfcal.min_search_radius_px, "Smallest search radius, px")->capture_default_str();
  cmd->add_option("--tolerance", args->options.selfcal.tolerance_px, "Converged when every camera's mean disparity is below this, px")
      ->capture_default_str();
  cmd->add_option("--max-iterations", args->options.selfcal.max_iterations, "Corrections at most")->capture_default_str();
  cmd->add_option("--peak-threshold", args->options.selfcal.peak_threshold,
                  "Particle peaks below this (counts) are ignored; 0: 10% of each image's 99.9th percentile")
      ->capture_default_str();
  cmd->add_option("--min-matches", args->options.selfcal.min_matches_per_subvolume, "Matches a sub-volume needs near its disparity peak")
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
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run(*args); });
}

}  // namespace tomorig::app
