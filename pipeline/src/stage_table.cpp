#include <charconv>
#include <cmath>
#include <utility>
#include <vector>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/stage.h"

namespace tomorig::pipeline {
namespace {

// "12" -> 12, "0.5" -> 0.5, "true" -> true, anything else stays a string.
nlohmann::json typed_value(const std::string& text) {
  if (text == "true") return true;
  if (text == "false") return false;
  std::int64_t whole = 0;
  auto [end_i, ec_i] = std::from_chars(text.data(), text.data() + text.size(), whole);
  if (ec_i == std::errc() && end_i == text.data() + text.size() && !text.empty()) return whole;
  double real = 0;
  auto [end_d, ec_d] = std::from_chars(text.data(), text.data() + text.size(), real);
  if (ec_d == std::errc() && end_d == text.data() + text.size() && !text.empty() && std::isfinite(real)) return real;
  return text;
}

}  // namespace

StageTable::StageTable(nlohmann::json values, std::string stage) : values_(std::move(values)), stage_(std::move(stage)) {
  if (values_.is_null()) values_ = nlohmann::json::object();
  if (!values_.is_object()) throw bad_input(fmt::format("stage '{}': its settings must be a table of keys", stage_));
}

StageTable StageTable::parse(const std::string& text, std::string stage) {
  // Split at commas; a part without '=' continues the previous value, so "window=32,32,16"
  // keeps its commas.
  std::vector<std::pair<std::string, std::string>> pairs;
  std::size_t start = 0;
  while (start <= text.size() && !text.empty()) {
    std::size_t comma = text.find(',', start);
    if (comma == std::string::npos) comma = text.size();
    const std::string item = text.substr(start, comma - start);
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos && !pairs.empty()) {
      pairs.back().second += "," + item;
    } else if (eq == std::string::npos || eq == 0) {
      throw bad_input(fmt::format("stage '{}': '{}' is not key=value (settings are key=value,key=value)", stage, item));
    } else {
      pairs.emplace_back(item.substr(0, eq), item.substr(eq + 1));
    }
    start = comma + 1;
  }
  nlohmann::json values = nlohmann::json::object();
  for (const auto& [key, value] : pairs) values[key] = typed_value(value);
  return StageTable(std::move(values), std::move(stage));
}

const nlohmann::json* StageTable::find(const std::string& key) const {
  used_.insert(key);
  const auto it = values_.find(key);
  return it == values_.end() ? nullptr : &*it;
}

bool StageTable::has(const std::string& key) const { return find(key) != nullptr; }

double StageTable::number(const std::string& key, double absent) const {
  const nlohmann::json* v = find(key);
  if (v == nullptr) return absent;
  if (!v->is_number())
    throw bad_input(fmt::format("stage '{}': {} = {} is not a number", stage_, key, v->dump()));
  return v->get<double>();
}

std::int64_t StageTable::integer(const std::string& key, std::int64_t absent) const {
  const nlohmann::json* v = find(key);
  if (v == nullptr) return absent;
  if (!v->is_number_integer())
    throw bad_input(fmt::format("stage '{}': {} = {} is not a whole number", stage_, key, v->dump()));
  return v->get<std::int64_t>();
}

bool StageTable::flag(const std::string& key, bool absent) const {
  const nlohmann::json* v = find(key);
  if (v == nullptr) return absent;
  if (!v->is_boolean()) throw bad_input(fmt::format("stage '{}': {} = {} is not true or false", stage_, key, v->dump()));
  return v->get<bool>();
}

std::string StageTable::text(const std::string& key, const std::string& absent) const {
  const nlohmann::json* v = find(key);
  if (v == nullptr) return absent;
  return v->is_string() ? v->get<std::string>() : v->dump();  // 32,32,32 or 0.5 read as text too
}

void StageTable::check_all_used() const {
  for (const auto& [key, value] : values_.items())
    if (!used_.contains(key)) {
      std::string known;
      for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
      throw bad_input(fmt::format("stage '{}' has no setting '{}'; its settings are: {}", stage_, key,
                                  known.empty() ? "(none)" : known));
    }
}

std::string StageReport::brief() const {
  std::string text = fmt::format("{}: {} of {} sets", name, processed, offered);
  if (skipped > 0) text += fmt::format(" ({} skipped to stay current)", skipped);
  text += fmt::format(", {:.2f} s busy", busy_seconds);
  if (!error.empty()) text += "; stopped: " + error;
  return text;
}

nlohmann::json StageReport::to_json() const {
  return {{"stage", name},     {"offered", offered}, {"processed", processed}, {"skipped", skipped},
          {"busy_seconds", busy_seconds}, {"error", error}, {"status", status}};
}

}  // namespace tomorig::pipeline
