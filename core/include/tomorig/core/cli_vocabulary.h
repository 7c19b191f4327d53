#pragma once
// The option vocabulary shared by every command (docs/cli.md, "Option vocabulary"), parsed in
// one place: the session as a positional argument, Δt with its unit in the value, and old
// spellings kept for one release as hidden aliases that print a deprecation warning.
// Set selection has its own header (set_selection.h).
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

namespace tomorig::cli {

// "80us", "1.5ms", "200ns", "80 µs", "0.001s" -> nanoseconds (>= 0; 0 is left to the command). A number without a unit is
// refused (was it µs or ns?). Throws tomorig::Error (bad_input) naming `option`.
double parse_duration_ns(std::string_view text, std::string_view option = "--dt");

// Prints (once per spelling and process) "warning: OLD is deprecated and will be removed in the
// next release; use NEW". Returns true the first time.
bool warn_deprecated(std::string_view old_spelling, std::string_view use_instead);

// OLD as a hidden option that stores into `target` like the new one, warning when used.
template <class T>
CLI::Option* add_deprecated_option(CLI::App& cmd, const std::string& old_name, T& target,
                                   const std::string& use_instead) {
  CLI::Option* o = cmd.add_option(old_name, target, "deprecated: use " + use_instead);
  o->group("");  // hidden from --help; docs/cli.md lists the old spellings
  const std::string shown = old_name.substr(0, old_name.find(','));
  o->each([shown, use_instead](const std::string&) { warn_deprecated(shown, use_instead); });
  return o;
}

// The session: a positional SESSION, and the old `--session FILE` kept as a deprecated alias
// where the command had it (`had_option`). Not marked required for CLI11 (either spelling
// will do): the command calls require_session() first.
void add_session_argument(CLI::App& cmd, std::string& session, const std::string& help, bool had_option = true);
// Throws bad_input("tomorig COMMAND: no session given; ...") when `session` is empty.
void require_session(const std::string& session, std::string_view command);

// --dt with units ("80us"), and the old --dt-us / --dt-ns (plain numbers) as deprecated aliases;
// `dt_ns` is set to the value in nanoseconds when any is given.
void add_dt_option(CLI::App& cmd, std::optional<double>& dt_ns, const std::string& help);

// `--json [FILE]`: the word after --json is its FILE only when it names a .json file (or is
// "-", stdout); otherwise it is the command's own argument, as in `tomorig inspect --json s.h5`,
// and --json is moved to the end of the command line, where it takes no value. `--json=FILE`
// always names a file. Applied to the whole command line (without the program name) before
// parsing.
std::vector<std::string> apply_json_value_rule(std::vector<std::string> args);

}  // namespace tomorig::cli
