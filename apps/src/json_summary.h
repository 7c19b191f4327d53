#pragma once
// `--json [FILE]`, the same for every summarising command: the summary as one JSON object on
// stdout (`--json`, and nothing else on stdout), or written to FILE (`--json=FILE` or
// `--json FILE.json`; `--json -` is stdout) with the usual text on stdout. The word after --json
// is its FILE only if it ends in .json (core/cli_vocabulary.h, apply_json_value_rule), so
// `tomorig inspect --json s.h5` still reads s.h5. The keys every summary shares are named here,
// once (docs/cli.md, "Output conventions").
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace tomorig::app {

namespace json_key {
inline constexpr const char* kCommand = "command";  // "simulate", "import", ...
inline constexpr const char* kOut = "out";          // the file written
inline constexpr const char* kSets = "sets";        // sets written (or sent)
inline constexpr const char* kCameras = "cameras";
inline constexpr const char* kSeconds = "seconds";  // wall time of the command's work
}  // namespace json_key

struct JsonOutput {
  CLI::Option* flag = nullptr;
  std::string file;  // empty: stdout
  bool wanted() const { return flag != nullptr && flag->count() > 0; }
  bool to_stdout() const { return wanted() && (file.empty() || file == "-"); }
};

void add_json_flag(CLI::App& cmd, JsonOutput& out);

// { "command": command } with the shared keys that are known up front.
nlohmann::json json_summary(const std::string& command);

// Prints or writes the summary if --json was given; a file is written whole (via a temporary).
void emit_json(const JsonOutput& out, const nlohmann::json& summary);

}  // namespace tomorig::app
