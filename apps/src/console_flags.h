#pragma once
// --quiet and --verbose, registered here for every command and subcommand (after all commands
// are added), so each accepts them after its name: `tomorig process -q ...`.
#include <CLI/CLI.hpp>

namespace tomorig::app {

void add_console_flags(CLI::App& root);

}  // namespace tomorig::app
