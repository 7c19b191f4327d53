// tomorig config check FILE | tomorig config default
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::app {
namespace {

// One line, enough to see that the file says what its author meant.
std::string summary(const config::RigConfig& rig) {
  int simulated = 0;
  for (const auto& cam : rig.cameras) simulated += cam.backend == config::CameraBackend::simulated ? 1 : 0;
  const auto& g = rig.grid;
  std::string line = fmt::format(
      "\"{}\": {} camera{} ({} simulated, {} aravis), {} trigger at {} Hz with dt {} us, grid {}x{}x{} at {} mm, "
      "{} x{}",
      rig.name, rig.cameras.size(), rig.cameras.size() == 1 ? "" : "s", simulated, rig.cameras.size() - simulated,
      config::to_string(rig.trigger.backend), rig.trigger.rate_hz, rig.trigger.dt_us, g.nx, g.ny, g.nz,
      g.voxel_size_mm, rig.processing.algorithm, rig.processing.iterations);
  if (rig.simulation) line += fmt::format(", simulation {}", rig.simulation->case_name);
  return line;
}

}  // namespace

void add_config_command(CLI::App& root) {
  CLI::App* config = root.add_subcommand("config", "Check a rig configuration file or print the default one");
  config->require_subcommand(1);

  CLI::App* check = config->add_subcommand(
      "check",
      "Validate a rig configuration (TOML). Prints 'FILE: ok' and a summary, or every problem "
      "with its line and key path (exit code 2)");
  auto file = std::make_shared<std::string>();
  check->add_option("FILE", *file, "Rig configuration file to check")->required();
  check->callback([file] {
    // A bad file throws tomorig::Error (bad_input) listing every issue; main.cpp prints it
    // and exits with 2.
    const config::RigConfig rig = config::load_rig_config(*file);
    fmt::print("{}: ok ({})\n", *file, summary(rig));
  });

  CLI::App* print_default = config->add_subcommand(
      "default",
      "Print the built-in default rig (the simulated 4-camera tpiv-thesis rig) as commented TOML, "
      "a starting point for your own: tomorig config default > rig.toml");
  print_default->callback([] { fmt::print("{}", config::default_rig_toml()); });
}

}  // namespace tomorig::app
