#pragma once
// Checked reading of one TOML table for the optics files (optics_setup.cpp, psf_table.cpp):
// every error names the file, the key path and the line, and what is allowed.
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"

namespace tomorig::optics::detail {

class TomlReader {
 public:
  TomlReader(const std::string& source, std::string path, config::TomlNode table)
      : source_(source), path_(std::move(path)), table_(table) {}

  [[noreturn]] void fail(const std::string& key, config::TomlNode node, const std::string& problem) const {
    const int line = node ? node.line() : table_.line();
    const std::string where = path_.empty() ? key : (key.empty() ? path_ : path_ + "." + key);
    throw bad_input(fmt::format("{}: {} (line {}): {}", source_, where, line, problem));
  }
  void only(const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : table_.entries()) {
      if (allowed.count(key)) continue;
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      fail(key, value, "is not a key here; allowed: " + list);
    }
  }
  bool has(const char* key) const { return table_.contains(key); }
  double number(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n) fail(key, {}, "is required");
    return as_number(key, n);
  }
  double as_number(const std::string& key, config::TomlNode n) const {
    if (!n.is_number()) fail(key, n, "must be a number");
    const double v = n.is_integer() ? static_cast<double>(*n.as_integer()) : *n.as_double();
    if (!std::isfinite(v)) fail(key, n, "must be a finite number");
    return v;
  }
  std::string string(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n) fail(key, {}, "is required");
    if (!n.is_string()) fail(key, n, "must be a string");
    return *n.as_string();
  }
  std::vector<double> numbers(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n) fail(key, {}, "is required");
    if (!n.is_array() || n.size() == 0) fail(key, n, "must be a non-empty array of numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < n.size(); ++i) out.push_back(as_number(fmt::format("{}[{}]", key, i), n[i]));
    return out;
  }
  config::TomlNode node(const char* key) const { return table_[key]; }

 private:
  const std::string& source_;
  std::string path_;
  config::TomlNode table_;
};

}  // namespace tomorig::optics::detail
