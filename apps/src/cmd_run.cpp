// tomorig run: the main job on a rig config. With no arguments it runs the embedded default,
// the simulated 4-camera tpiv-thesis rig, and records a session file.
#include <chrono>
#include <ctime>
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/core.h>

#include "commands.h"
#include "stop_signal.h"
#include "tomorig/trigger/rig_trigger.h"
#include "simulate_session.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {
namespace {

struct RunOptions {
  std::string config_path;
  std::string out;
  std::optional<int> sets;
  std::string compression = "none";
  bool overwrite = false;
};

std::filesystem::path default_output_path() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  return std::filesystem::path("runs") / fmt::format("session-{}.h5", stamp);
}

void run(const RunOptions& opt) {
  config::RigConfig rig = opt.config_path.empty() ? config::default_rig_config()
                                                  : config::load_rig_config(opt.config_path);
  for (const auto& cam : rig.cameras)
    if (cam.backend != config::CameraBackend::simulated)
      throw runtime_error(fmt::format(
          "cameras '{}' uses the {} backend, which this build cannot drive yet; "
          "use backend = \"simulated\" or record with another tool and 'tomorig import'",
          cam.id, config::to_string(cam.backend)));
  if (!rig.simulation)
    throw bad_input("the rig has simulated cameras but no [simulation] table; add one "
                    "(see 'tomorig config default')");
  if (opt.sets) {
    if (*opt.sets < 1) throw bad_input(fmt::format("--sets {} is invalid: must be >= 1", *opt.sets));
    rig.simulation->sets = *opt.sets;
  }
  const auto compression = storage::parse_compression(opt.compression);
  if (!compression)
    throw bad_input(fmt::format("--compression {} is not supported (none, bitshuffle-lz4)", opt.compression));

  std::filesystem::path out = opt.out.empty() ? default_output_path() : std::filesystem::path(opt.out);
  if (out.has_parent_path()) {
    std::error_code ec;
    std::filesystem::create_directories(out.parent_path(), ec);
    if (ec)
      throw bad_input(fmt::format("cannot create the output folder {}: {}; choose another --out",
                                  out.parent_path().string(), ec.message()));
  }

  // The trigger timing and the light sources' safety limits are checked before anything runs.
  trigger::plan_and_check(trigger::rig_trigger(rig));
  fmt::print("tomorig run: rig '{}', {} cameras, {} sets, case {} at {} ppp\n", rig.name, rig.cameras.size(),
             rig.simulation->sets, rig.simulation->case_name, rig.simulation->ppp);
  const auto started = std::chrono::steady_clock::now();
  auto progress = [started](std::uint64_t done, std::uint64_t total, double /*set_seconds*/) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const double eta = done > 0 ? elapsed / static_cast<double>(done) * static_cast<double>(total - done) : 0.0;
    fmt::print(stderr, "\rrecording: set {}/{}  {:.1f} sets/s  ETA {:.1f} s", done, total,
               elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0, eta);
    if (done == total) fmt::print(stderr, "\n");
  };
  // Ctrl-C ends the recording between sets with a complete, valid file; a second Ctrl-C quits.
  const StopSignalGuard stop;
  const SimulationSummary summary = run_simulation_to_session(rig, out, *compression, opt.overwrite, progress,
                                                              /*live=*/true, [&stop] { return stop.stop_requested(); });
  if (stop.stop_requested())
    fmt::print(stderr, "\nstopped by {} after {} of {} sets; the session is complete\n", stop.signal_name(),
               summary.sets, rig.simulation->sets);
  fmt::print("{}\n", summary.brief());
  fmt::print("next: tomorig inspect {}\n", summary.output.string());
}

}  // namespace

void add_run_command(CLI::App& root) {
  auto opt = std::make_shared<RunOptions>();
  CLI::App* cmd = root.add_subcommand(
      "run", "Run the rig: trigger, acquire and record a session (default: the embedded simulated "
             "4-camera tpiv-thesis rig)");
  cmd->add_option("-c,--config", opt->config_path, "Rig file (TOML); default: the embedded rig")
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--out", opt->out, "Session file to write; default: runs/session-<UTC time>.h5");
  cmd->add_option("--sets", opt->sets, "Number of double-frame sets to record (overrides the rig file)");
  cmd->add_option("--compression", opt->compression, "Frame compression: none | bitshuffle-lz4");
  cmd->add_flag("--overwrite", opt->overwrite, "Replace an existing output file");
  cmd->callback([opt] { run(*opt); });
}

}  // namespace tomorig::app
