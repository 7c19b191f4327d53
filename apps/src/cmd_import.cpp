// tomorig import: image sequences from other software -> a session file.
#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "tomorig/core/cli_vocabulary.h"
#include "json_summary.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/image_import.h"

namespace tomorig::app {
namespace {

struct ImportArgs {
  std::vector<std::string> cameras;  // "ID=PATTERN"
  std::string pairing = "auto";
  JsonOutput json;
  std::optional<double> dt_ns;  // --dt (0: unknown); none: the rig config's
  double pixel_pitch_um = 0.0;
  double rate_hz = 0.0;
  std::string config;
  std::string compression = "none";
  bool overwrite = false;
  std::string out;
  // Set while registering: whether a flag was given, so it can override the rig config.
  CLI::Option* pitch_flag = nullptr;
  CLI::Option* rate_flag = nullptr;
};

storage::ImportCamera parse_camera(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
    throw bad_input(fmt::format("--camera '{}' should be ID=PATTERN, e.g. --camera 'cam0=cam0.pre/im*.tif'", spec));
  storage::ImportCamera camera;
  camera.id = spec.substr(0, eq);
  camera.pattern = spec.substr(eq + 1);
  return camera;
}

// Takes Δt, rate and pixel pitches from the rig file for whatever the flags leave open.
void apply_rig(const config::RigConfig& rig, const std::string& origin, storage::ImportOptions& o,
               const ImportArgs& args) {
  if (!args.dt_ns) o.dt_us = rig.trigger.dt_us;
  if (!*args.rate_flag) o.rate_hz = rig.trigger.rate_hz;
  o.rig_config_toml = rig.source_text;
  for (auto& camera : o.cameras) {
    const auto it = std::find_if(rig.cameras.begin(), rig.cameras.end(),
                                 [&](const config::CameraConfig& c) { return c.id == camera.id; });
    if (it == rig.cameras.end()) {
      std::string known;
      for (const auto& c : rig.cameras) known += (known.empty() ? "" : ", ") + c.id;
      throw bad_input(fmt::format("camera '{}' is not in rig config '{}' (cameras: {})", camera.id, origin, known));
    }
    if (!*args.pitch_flag) camera.pixel_pitch_um = it->pixel_pitch_um;
  }
}

void run_import(const ImportArgs& args) {
  storage::ImportOptions o;
  for (const auto& spec : args.cameras) o.cameras.push_back(parse_camera(spec));
  const auto pairing = storage::parse_frame_pairing(args.pairing);
  const auto compression = storage::parse_compression(args.compression);
  if (!pairing || !compression) throw bad_input("invalid --pair or --compression");  // CLI11 checks these first
  o.pairing = *pairing;
  o.writer.compression = *compression;
  o.writer.overwrite = args.overwrite;
  o.dt_us = args.dt_ns.value_or(0.0) * 1e-3;
  o.rate_hz = args.rate_hz;
  for (auto& camera : o.cameras) camera.pixel_pitch_um = args.pixel_pitch_um;
  if (!args.config.empty()) {
    apply_rig(config::load_rig_config(args.config), args.config, o, args);
  } else if (!args.dt_ns) {
    // A session without Δt cannot give velocities; make the user say so explicitly.
    throw bad_input("import needs the pulse separation: pass --dt with its unit (e.g. --dt 80us; --dt 0us if unknown) "
                    "or --config RIG.toml");
  }

  const storage::ImportResult result = storage::import_images(o, args.out);
  nlohmann::json j = json_summary("import");
  j[json_key::kOut] = result.output.string();
  j[json_key::kSets] = result.sets;
  j["pairing"] = std::string(to_string(result.plan.pairing));
  j["compression"] = std::string(to_string(o.writer.compression));
  j["dt_us"] = o.dt_us;
  j[json_key::kCameras] = nlohmann::json::array();
  for (std::size_t c = 0; c < result.cameras.size(); ++c)
    j[json_key::kCameras].push_back({{"id", result.cameras[c].id},
                                     {"width", result.cameras[c].width},
                                     {"height", result.cameras[c].height},
                                     {"pixel_format", std::string(to_string(result.cameras[c].pixel_format))},
                                     {"files", result.plan.cameras[c].files.size()}});
  if (args.json.to_stdout()) {
    emit_json(args.json, j);
    return;
  }
  fmt::print("imported {} set{} from {} camera{} into {} (frames paired by {}, compression {})\n", result.sets,
             result.sets == 1 ? "" : "s", result.cameras.size(), result.cameras.size() == 1 ? "" : "s",
             result.output.string(), to_string(result.plan.pairing), to_string(o.writer.compression));
  for (std::size_t c = 0; c < result.cameras.size(); ++c) {
    const auto& cam = result.cameras[c];
    const auto& planned = result.plan.cameras[c];
    fmt::print("  {:<10} {} x {}  {:<6}  {} file{}, first {}\n", cam.id, cam.width, cam.height,
               to_string(cam.pixel_format), planned.files.size(), planned.files.size() == 1 ? "" : "s",
               planned.files.front().string());
  }
  fmt::print("dt {:g} us, pixel pitch {}\n", o.dt_us,
             o.cameras.front().pixel_pitch_um > 0 ? fmt::format("{:g} um", o.cameras.front().pixel_pitch_um)
                                                  : std::string("unknown"));
  emit_json(args.json, j);
}

}  // namespace

void add_import_command(CLI::App& root) {
  auto args = std::make_shared<ImportArgs>();
  CLI::App* cmd = root.add_subcommand("import", "Build a session file from TIFF/PNG image sequences");
  cmd->add_option("--camera", args->cameras,
                  "ID=PATTERN, once per camera in camera order, e.g. --camera 'cam0=cam0.pre/im*.tif' (quote the "
                  "pattern so the shell does not expand it)")
      ->required();
  cmd->add_option("--pair", args->pairing,
                  "How frames form sets: name (im00001a + im00001b), order (consecutive frames), auto (name if "
                  "every file name ends in a/b)")
      ->check(CLI::IsMember({"auto", "name", "order"}))
      ->capture_default_str();
  cli::add_dt_option(*cmd, args->dt_ns, "Pulse separation A -> B, 0us if unknown");
  args->pitch_flag = cmd->add_option("--pixel-pitch-um", args->pixel_pitch_um, "Sensor pixel pitch in micrometres");
  args->rate_flag = cmd->add_option("--rate-hz", args->rate_hz,
                                    "Trigger rate, to give sets timestamps i / rate (0 = unknown: all at t = 0)");
  cmd->add_option("--config", args->config,
                  "Rig config (TOML): supplies dt, rate and pixel pitch unless given as flags, and is stored in "
                  "the session");
  cmd->add_option("--compression", args->compression, "Frame compression: none or bitshuffle-lz4")
      ->check(CLI::IsMember({"none", "bitshuffle-lz4"}))
      ->capture_default_str();
  cmd->add_flag("--overwrite", args->overwrite, "Replace the output file if it exists");
  cmd->add_option("--out,-o", args->out, "Output session file (.h5)")->required();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { run_import(*args); });
}

}  // namespace tomorig::app
