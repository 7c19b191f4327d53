#include "console_flags.h"

#include "tomorig/core/console.h"

namespace tomorig::app {
namespace {

void add_to(CLI::App& app) {
  if (!app.get_option_no_throw("--quiet"))
    app.add_flag_callback("-q,--quiet", [] { set_verbosity(Verbosity::quiet); },
                          "Print only warnings, errors and results (no progress)");
  if (!app.get_option_no_throw("--verbose"))
    app.add_flag_callback("-v,--verbose", [] { set_verbosity(Verbosity::verbose); },
                          "Also print debug messages (e.g. a line per set)");
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) add_to(*sub);
}

}  // namespace

void add_console_flags(CLI::App& root) {
  set_verbosity(Verbosity::normal);
  add_to(root);
}

}  // namespace tomorig::app
