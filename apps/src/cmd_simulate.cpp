// tomorig simulate: render a built-in synthetic case into a session file with ground truth.
//   tomorig simulate --case tpiv-thesis --ppp 0.05 --sets 2 --seed 1 --out s.h5
// The rig comes from --config (or the embedded default rig); flags override its
// [simulation] section. The work is in simulate_session.cpp, shared with `tomorig run`.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/console.h"
#include "tomorig/rig/simulate_calib_target.h"
#include "tomorig/rig/simulate_session.h"
#include "tomorig/rig/simulate_spray.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/calibration_target.h"
#include "tomorig/simulators/cases.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {

using rig::SimulationSummary;
using rig::run_simulation_to_session;
using rig::write_calib_target_session;

namespace {

struct SimulateFlags {
  std::string case_name;
  double ppp = 0.0;
  int sets = 0;
  std::uint64_t seed = 0;
  std::string out;
  std::string config;
  bool noise = false;
  int bit_depth = 0;
  std::string compression = "none";
  bool overwrite = false;
  bool reduced = false;
  bool targets = false;
  double distortion_px = sim::CalibTargetOptions{}.distortion_corner_px;
  std::string spray = sim::to_string(sim::SprayOptions{}.pattern);
  // Which optional flags were given: only those override the rig config.
  CLI::Option* case_opt = nullptr;
  CLI::Option* ppp_opt = nullptr;
  CLI::Option* sets_opt = nullptr;
  CLI::Option* seed_opt = nullptr;
  CLI::Option* bit_depth_opt = nullptr;
  CLI::Option* distortion_opt = nullptr;
  CLI::Option* spray_opt = nullptr;
  JsonOutput json;
};

// calib-thesis is a target case, not a particle case: it has its own renderer and writes one
// set per traverse plane (simulate_calib_target.h). Noise is always on; --seed picks the stage
// errors and the noise.
void run_calib_thesis(const SimulateFlags& f, storage::Compression compression) {
  if (f.ppp_opt->count() || f.sets_opt->count() || f.bit_depth_opt->count() || !f.config.empty())
    throw bad_input("--case calib-thesis takes no --ppp, --sets, --bit-depth or --config: it renders one set per "
                    "traverse plane of a chessboard target (16-bit)");
  sim::CalibTargetOptions o;
  o.reduced = f.reduced;
  if (f.seed_opt->count()) o.seed = f.seed;
  o.distortion_corner_px = f.distortion_px;
  const std::string written = write_calib_target_session(o, f.out, compression, f.overwrite);
  if (!f.json.to_stdout()) fmt::print("{}\n", written);
  nlohmann::json j = json_summary("simulate");
  j[json_key::kOut] = f.out;
  j["case"] = "calib-thesis";
  emit_json(f.json, j);
}

// spray-thesis is a shadowgraphy case with its own renderer (spray.h, simulate_spray.h):
// droplets, LED bright field and the visibility truth. Noise is always on.
void run_spray_thesis(const SimulateFlags& f, storage::Compression compression) {
  if (f.ppp_opt->count() || f.bit_depth_opt->count() || f.distortion_opt->count() || !f.config.empty())
    throw bad_input("--case spray-thesis takes no --ppp, --bit-depth, --distortion-px or --config: it renders a droplet "
                    "field (--spray hollow-cone or jet-in-crossflow) on 16-bit cameras");
  sim::SprayOptions o;
  o.reduced = f.reduced;
  if (f.seed_opt->count()) o.seed = f.seed;
  o.pattern = rig::parse_spray_pattern(f.spray, "--spray");
  std::string written;
  if (f.targets) {
    if (f.sets_opt->count()) throw bad_input("--targets renders one set per PSF depth (13): --sets does not apply");
    written = rig::write_spray_target_session(o, f.out, compression, f.overwrite);
  } else {
    const int sets = f.sets_opt->count() ? f.sets : 2;
    written = rig::write_spray_session(o, sets, f.out, compression, f.overwrite, [](int done, int total) {
      fmt::print(stderr, "set {}/{} rendered\n", done, total);
      std::fflush(stderr);
    });
  }
  if (!f.json.to_stdout()) fmt::print("{}\n", written);
  nlohmann::json j = json_summary("simulate");
  j[json_key::kOut] = f.out;
  j["case"] = f.targets ? "spray-thesis targets" : "spray-thesis";
  emit_json(f.json, j);
}

void run_simulate(const SimulateFlags& f) {
  const auto compression = storage::parse_compression(f.compression);
  if (!compression)
    throw bad_input(fmt::format("--compression '{}' is unknown: use none or bitshuffle-lz4", f.compression));

  if (f.case_opt->count() && f.case_name == "calib-thesis") return run_calib_thesis(f, *compression);
  if (f.case_opt->count() && f.case_name == "spray-thesis") return run_spray_thesis(f, *compression);
  if (f.spray_opt->count() || f.targets) throw bad_input("--spray and --targets apply to --case spray-thesis only");
  if (f.reduced || f.distortion_opt->count())
    throw bad_input("--reduced applies to --case spray-thesis or calib-thesis only, --distortion-px to calib-thesis only");

  config::RigConfig rig = f.config.empty() ? config::default_rig_config() : config::load_rig_config(f.config);
  if (!rig.simulation) rig.simulation.emplace();
  config::SimulationConfig& s = *rig.simulation;

  // Overrides are recorded as TOML comments after the config text: the text stays valid TOML
  // and the session still says how its values came about (the truth holds the values used).
  std::vector<std::string> overrides;
  if (f.case_opt->count()) {
    s.case_name = f.case_name;
    overrides.push_back(fmt::format("simulation.case_name = \"{}\"", f.case_name));
  }
  if (f.ppp_opt->count()) {
    s.ppp = f.ppp;
    overrides.push_back(fmt::format("simulation.ppp = {}", f.ppp));
  }
  if (f.sets_opt->count()) {
    if (f.sets < 1) throw bad_input(fmt::format("--sets {} is invalid: it must be >= 1", f.sets));
    s.sets = f.sets;
    overrides.push_back(fmt::format("simulation.sets = {}", f.sets));
  }
  if (f.seed_opt->count()) {
    s.seed = f.seed;
    overrides.push_back(fmt::format("simulation.seed = {}", f.seed));
  }
  if (f.noise) {
    s.noise = true;
    overrides.push_back("simulation.noise = true");
  }
  if (f.bit_depth_opt->count()) {
    if (f.bit_depth != 12 && f.bit_depth != 16)
      throw bad_input(fmt::format("--bit-depth {} is not supported: use 12 or 16", f.bit_depth));
    s.bit_depth = f.bit_depth;
    overrides.push_back(fmt::format("simulation.bit_depth = {}", f.bit_depth));
  }
  // The simulated cameras record what the sensor model quantises to (an unsupported bit
  // depth is reported by simulation_options_from).
  if (s.bit_depth == 12 || s.bit_depth == 16) {
    const PixelFormat format = s.bit_depth == 12 ? PixelFormat::Mono12 : PixelFormat::Mono16;
    for (config::CameraConfig& c : rig.cameras)
      if (c.backend == config::CameraBackend::simulated && c.pixel_format != format) {
        c.pixel_format = format;
        overrides.push_back(fmt::format("cameras['{}'].pixel_format = \"{}\"", c.id, to_string(format)));
      }
  }
  if (!overrides.empty()) {
    rig.source_text += "\n# Overridden on the command line by `tomorig simulate`:\n";
    for (const std::string& o : overrides) rig.source_text += "#   " + o + "\n";
  }

  StatusLine status;
  const SimulationSummary summary = run_simulation_to_session(
      rig, f.out, *compression, f.overwrite, [&](std::uint64_t done, std::uint64_t total, double seconds) {
        const auto text = [&] { return fmt::format("simulate: set {}/{} rendered ({:.2f} s)", done, total, seconds); };
        if (done == total) status.finish(text());
        else if (status.due()) status.update(text());
      });
  if (!f.json.to_stdout()) fmt::print("{}\n", summary.brief());
  nlohmann::json j = json_summary("simulate");
  j[json_key::kOut] = summary.output.string();
  j[json_key::kSets] = summary.sets;
  j[json_key::kCameras] = summary.cameras;
  j[json_key::kSeconds] = summary.seconds;
  j["case"] = summary.case_name;
  j["particles_per_set"] = summary.particles_per_set;
  j["bytes"] = summary.bytes;
  emit_json(f.json, j);
}

}  // namespace

void add_simulate_command(CLI::App& root) {
  auto flags = std::make_shared<SimulateFlags>();
  CLI::App* cmd = root.add_subcommand(
      "simulate", "Render a built-in synthetic case into a session file (HDF5) with its ground truth");
  flags->case_opt =
      cmd->add_option("--case", flags->case_name, "simulation case: " + sim::case_names() + ", calib-thesis, spray-thesis");
  flags->ppp_opt = cmd->add_option("--ppp", flags->ppp, "particle images per pixel, in (0, 1]");
  flags->sets_opt = cmd->add_option("--sets", flags->sets, "number of double-frame sets to render");
  flags->seed_opt = cmd->add_option("--seed", flags->seed, "random seed (recorded in the truth)");
  cmd->add_option("-o,--out", flags->out, "session file to write (.h5)")->required();
  cmd->add_option("--config", flags->config, "rig config (TOML); default: the embedded tpiv-thesis rig");
  cmd->add_flag("--noise", flags->noise, "add shot and read noise");
  flags->bit_depth_opt = cmd->add_option("--bit-depth", flags->bit_depth, "sensor bit depth: 12 or 16");
  cmd->add_option("--compression", flags->compression, "frame compression: none or bitshuffle-lz4")
      ->capture_default_str();
  cmd->add_flag("--overwrite", flags->overwrite, "replace an existing output file");
  cmd->add_flag("--reduced", flags->reduced, "calib-thesis, spray-thesis: the reduced 640 x 540 variant (for tests)");
  flags->spray_opt = cmd->add_option("--spray", flags->spray, "spray-thesis: hollow-cone or jet-in-crossflow")
                         ->capture_default_str();
  cmd->add_flag("--targets", flags->targets,
                "spray-thesis: the knife-edge calibration series (one set per PSF depth) instead of droplets");
  flags->distortion_opt = cmd->add_option("--distortion-px", flags->distortion_px,
                                          "calib-thesis: radial lens distortion at the image corner, full-size px");
  add_json_flag(*cmd, flags->json);
  cmd->callback([flags] { run_simulate(*flags); });
}

}  // namespace tomorig::app
