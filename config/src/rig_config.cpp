// The public entry points: parse -> decode -> collect issues -> throw or return.
#include "tomorig/config/rig_config.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "decode.h"
#include "embedded_default.h"
#include "tomorig/core/error.h"

namespace tomorig::config {
namespace {

struct Checked {
  RigConfig rig;
  std::vector<ConfigIssue> issues;
};

Checked parse_and_check(const std::string& toml_text, const std::string& origin) {
  Checked out;
  try {
    const toml::table root = toml::parse(std::string_view(toml_text), std::string_view(origin));
    out.rig = detail::decode_rig(root, out.issues);
  } catch (const toml::parse_error& e) {
    // toml++ stops at the first syntax error, so this is the only issue.
    ConfigIssue issue;
    issue.line = static_cast<int>(e.source().begin.line);
    issue.column = static_cast<int>(e.source().begin.column);
    issue.message = fmt::format("invalid TOML: {}", e.description());
    out.issues.push_back(std::move(issue));
  }
  for (auto& issue : out.issues) issue.origin = origin;
  // Reading order: the decoders visit keys in schema order and toml++ tables iterate
  // alphabetically, but a user fixes a file top to bottom.
  std::stable_sort(out.issues.begin(), out.issues.end(),
                   [](const ConfigIssue& a, const ConfigIssue& b) { return a.line < b.line; });
  out.rig.source_text = toml_text;
  return out;
}

std::string format_issues(const std::vector<ConfigIssue>& issues, const std::string& origin) {
  std::string message = fmt::format("{}: {} problem{} in the rig config:", origin, issues.size(),
                                    issues.size() == 1 ? "" : "s");
  for (const auto& issue : issues) {
    message += '\n';
    message += issue.to_string();
  }
  return message;
}

}  // namespace

std::string ConfigIssue::to_string() const {
  std::string out = origin;
  if (line > 0) {
    out += out.empty() ? fmt::format("line {}", line) : fmt::format(":{}", line);
    if (column > 0) out += fmt::format(":{}", column);
  }
  if (!out.empty()) out += ": ";
  if (!key.empty()) out += key + ": ";
  return out + message;
}

std::vector<ConfigIssue> check_rig_config(const std::string& toml_text, const std::string& origin) {
  return parse_and_check(toml_text, origin).issues;
}

RigConfig parse_rig_config(const std::string& toml_text, const std::string& origin) {
  Checked checked = parse_and_check(toml_text, origin);
  if (!checked.issues.empty()) throw bad_input(format_issues(checked.issues, origin));
  return std::move(checked.rig);
}

RigConfig load_rig_config(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw bad_input(fmt::format("rig config file \"{}\" does not exist", name));
  if (std::filesystem::is_directory(path, ec))
    throw bad_input(fmt::format("rig config \"{}\" is a directory, not a TOML file", name));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw bad_input(fmt::format("cannot open rig config \"{}\": {}", name, std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw bad_input(fmt::format("cannot read rig config \"{}\": {}", name, std::strerror(errno)));

  RigConfig rig = parse_rig_config(text.str(), name);
  // A relative calibration path means "next to the rig file", wherever tomorig is started.
  if (rig.calibration_file && rig.calibration_file->is_relative())
    rig.calibration_file = path.parent_path() / *rig.calibration_file;
  return rig;
}

const std::string& default_rig_toml() { return detail::embedded_default_rig_toml(); }

RigConfig default_rig_config() { return parse_rig_config(default_rig_toml(), "default-rig.toml"); }

}  // namespace tomorig::config
