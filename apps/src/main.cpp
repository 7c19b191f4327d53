// tomorig: the command line. Parses flags, calls the libraries, prints, and maps errors to
// exit codes here and nowhere else.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/core.h>

#include "commands.h"
#include "console_flags.h"
#include "exit_codes.h"
#include "tomorig/bench/bench_command.h"
#include "tomorig/core/cli_vocabulary.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"

int main(int argc, char** argv) {
  using namespace tomorig::app;
  CLI::App app{"tomorig: tomographic PIV and shadowgraphy acquisition and processing"};
  app.name("tomorig");  // parsed from a vector below, so argv[0] does not name it
  app.set_version_flag("--version", std::string(tomorig::software_version()));
  app.require_subcommand(1);
  app.footer("Exit codes: 0 ok, 1 runtime failure, 2 bad usage or bad input.\n"
             "Run 'tomorig <command> --help' for a command's options.");
  add_run_command(app);
  add_replay_command(app);
  add_record_command(app);
  add_acquire_command(app);
  add_simulate_command(app);
  add_import_command(app);
  add_inspect_command(app);
  add_calibrate_command(app);
  add_reconstruct_command(app);
  add_preprocess_command(app);
  add_selfcal_command(app);
  add_config_command(app);
  add_process_command(app);
  add_piv3d_command(app);
  add_stages_command(app);
  add_preview_command(app);
  add_optics_command(app);
  tomorig::bench::add_bench_command(app);
  add_trigger_command(app);
  add_console_flags(app);  // after every command: each gets --quiet and --verbose

  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    args = tomorig::cli::apply_json_value_rule(std::move(args));
    std::reverse(args.begin(), args.end());  // CLI11 takes a vector last-first
    app.parse(std::move(args));
    return kExitOk;
  } catch (const CLI::Success& e) {  // --help, --version
    app.exit(e);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitBadInput;
  } catch (const tomorig::Error& e) {
    std::fflush(stdout);
    fmt::print(stderr, "error: {}\n", e.what());
    return e.kind() == tomorig::ErrorKind::bad_input ? kExitBadInput : kExitRuntimeFailure;
  } catch (const std::exception& e) {
    std::fflush(stdout);
    fmt::print(stderr, "error: {}\n", e.what());
    return kExitRuntimeFailure;
  }
}
