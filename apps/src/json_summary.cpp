#include "json_summary.h"

#include <filesystem>
#include <fstream>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::app {

void add_json_flag(CLI::App& cmd, JsonOutput& out) {
  out.flag = cmd.add_option("--json", out.file,
                            "Print the summary as one JSON object on stdout (and nothing else there), or write "
                            "it to FILE (.json, or --json=FILE)")
                 ->expected(0, 1)
                 ->type_name("[FILE]");
}

nlohmann::json json_summary(const std::string& command) { return {{json_key::kCommand, command}}; }

// Strings in a summary may come from a damaged or hostile file (a version attribute with a flipped
// bit is not UTF-8): such bytes become U+FFFD instead of an exception that ends the command.
static std::string json_text(const nlohmann::json& summary) {
  return summary.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

void emit_json(const JsonOutput& out, const nlohmann::json& summary) {
  if (!out.wanted()) return;
  if (out.to_stdout()) {
    fmt::print("{}\n", json_text(summary));
    return;
  }
  const std::filesystem::path path(out.file), partial = path.string() + ".partial";
  {
    std::ofstream file(partial);
    file << json_text(summary) << "\n";
    if (!file.good())
      throw runtime_error(fmt::format("--json: cannot write '{}'; check the folder exists and is writable", out.file));
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) throw runtime_error(fmt::format("--json: cannot rename '{}' to '{}': {}", partial.string(), out.file, ec.message()));
}

}  // namespace tomorig::app
