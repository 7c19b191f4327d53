#pragma once
// Each subcommand lives in its own cmd_<name>.cpp and registers itself on the root app.
// A command's callback does the work and reports failure by throwing tomorig::Error;
// main.cpp maps errors to exit codes in one place (see docs/cli.md):
//   0 ok, 1 runtime failure, 2 bad usage or bad input.
#include <CLI/CLI.hpp>

namespace tomorig::app {

void add_config_command(CLI::App& root);    // cmd_config.cpp: config check | default
void add_simulate_command(CLI::App& root);  // cmd_simulate.cpp
void add_inspect_command(CLI::App& root);   // cmd_inspect.cpp
void add_import_command(CLI::App& root);    // cmd_import.cpp
void add_run_command(CLI::App& root);       // cmd_run.cpp: the main job on a rig config
void add_replay_command(CLI::App& root);   // cmd_replay.cpp
void add_record_command(CLI::App& root);   // cmd_record.cpp
void add_acquire_command(CLI::App& root);  // cmd_acquire.cpp: the acquisition half of a split rig
void add_trigger_command(CLI::App& root);   // cmd_trigger.cpp: trigger plan
void add_reconstruct_command(CLI::App& root);  // cmd_reconstruct.cpp
void add_calibrate_command(CLI::App& root);  // cmd_calibrate.cpp
void add_preprocess_command(CLI::App& root);  // cmd_preprocess.cpp
void add_selfcal_command(CLI::App& root);   // cmd_selfcal.cpp: volume self-calibration
void add_process_command(CLI::App& root);  // cmd_process.cpp: the back-end pipeline
void add_piv3d_command(CLI::App& root);    // cmd_piv3d.cpp: correlate two volumes
void add_stages_command(CLI::App& root);   // cmd_stages.cpp: list stages, run a chain over a session
void add_preview_command(CLI::App& root);  // cmd_preview.cpp: watch the quick-look of a run
void add_optics_command(CLI::App& root);   // cmd_optics.cpp: droplet imaging model, visibility

}  // namespace tomorig::app
