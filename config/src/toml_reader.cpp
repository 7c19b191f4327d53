#include "toml_reader.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "key_path.h"
#include "suggest.h"

namespace tomorig::config::detail {
namespace {

int line_of_node(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

ConfigIssue make_issue(std::string key, int line, std::string message) {
  ConfigIssue issue;
  issue.key = std::move(key);
  issue.line = line;
  issue.message = std::move(message);
  return issue;
}

std::string clipped(std::string_view s) {
  constexpr std::size_t kMax = 40;  // a value pasted into a message should not swamp it
  return s.size() <= kMax ? std::string(s) : std::string(s.substr(0, kMax)) + "...";
}

std::string render(const std::string& v) { return fmt::format("\"{}\"", clipped(v)); }
template <typename T>
std::string render(const T& v) { return fmt::format("{}", v); }

// What the file holds, for "expected a number, got string \"abc\"".
std::string describe(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::string: return "string " + render(std::string(node.as_string()->get()));
    case toml::node_type::integer: return fmt::format("integer {}", node.as_integer()->get());
    case toml::node_type::floating_point: {
      // "got float 512.0", not "got float 512", when the point is what makes it wrong.
      std::string text = fmt::format("{}", node.as_floating_point()->get());
      if (text.find_first_of(".ein") == std::string::npos) text += ".0";
      return "float " + text;
    }
    case toml::node_type::boolean: return fmt::format("boolean {}", node.as_boolean()->get());
    case toml::node_type::array: return "an array";
    case toml::node_type::table: return "a table";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

}  // namespace

TableReader::TableReader(const toml::table& table, std::string path, std::vector<ConfigIssue>& issues)
    : table_(&table), path_(std::move(path)), issues_(&issues),
      line_(path_.empty() ? 0 : static_cast<int>(table.source().begin.line)) {}

int TableReader::line_of(std::string_view key) const {
  const toml::node* node = table_->get(key);
  return node ? line_of_node(*node) : line_;
}

void TableReader::issue(std::string_view key, std::string message) {
  issues_->push_back(make_issue(child_path(path_, key), line_of(key), std::move(message)));
}

void TableReader::type_issue(std::string_view key, const toml::node& node, std::string_view expected) {
  issue(key, fmt::format("expected {}, got {}", expected, describe(node)));
}

const toml::node* TableReader::lookup(std::string_view key, Need need, std::string_view expected) {
  if (std::find(known_.begin(), known_.end(), key) == known_.end()) known_.emplace_back(key);
  const toml::node* node = table_->get(key);
  if (!node && need == Need::required) issue(key, fmt::format("required key is missing (expected {})", expected));
  return node;
}

namespace {
// Applies `rule` and assigns; shared by the scalar reads.
template <typename T>
bool accept(TableReader& reader, std::string_view key, const T& value, const Rule<T>& rule, T& out) {
  if (rule) {
    if (auto complaint = rule(value)) {
      reader.issue(key, fmt::format("{} {}", render(value), *complaint));
      return false;
    }
  }
  out = value;
  return true;
}
}  // namespace

bool TableReader::read(std::string_view key, std::string& out, Need need, const Rule<std::string>& rule) {
  const toml::node* node = lookup(key, need, "a string");
  if (!node) return false;
  if (!node->is_string()) {
    type_issue(key, *node, "a string");
    return false;
  }
  return accept(*this, key, std::string(node->as_string()->get()), rule, out);
}

bool TableReader::read(std::string_view key, int& out, Need need, const Rule<int>& rule) {
  const toml::node* node = lookup(key, need, "an integer");
  if (!node) return false;
  if (!node->is_integer()) {
    type_issue(key, *node, "an integer");
    return false;
  }
  const std::int64_t v = node->as_integer()->get();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    issue(key, fmt::format("{} is out of range for a 32-bit integer", v));
    return false;
  }
  return accept(*this, key, static_cast<int>(v), rule, out);
}

bool TableReader::read(std::string_view key, std::uint64_t& out, Need need, const Rule<std::uint64_t>& rule) {
  const toml::node* node = lookup(key, need, "a non-negative integer");
  if (!node) return false;
  if (!node->is_integer()) {
    type_issue(key, *node, "a non-negative integer");
    return false;
  }
  const std::int64_t v = node->as_integer()->get();
  if (v < 0) {
    issue(key, fmt::format("{} must be >= 0", v));
    return false;
  }
  return accept(*this, key, static_cast<std::uint64_t>(v), rule, out);
}

bool TableReader::read(std::string_view key, double& out, Need need, const Rule<double>& rule) {
  const toml::node* node = lookup(key, need, "a number");
  if (!node) return false;
  double v = 0.0;
  if (node->is_integer()) {
    v = static_cast<double>(node->as_integer()->get());  // "rate_hz = 10" is a number too
  } else if (node->is_floating_point()) {
    v = node->as_floating_point()->get();
  } else {
    type_issue(key, *node, "a number");
    return false;
  }
  if (!std::isfinite(v)) {
    issue(key, fmt::format("{} must be a finite number", v));
    return false;
  }
  return accept(*this, key, v, rule, out);
}

bool TableReader::read(std::string_view key, bool& out, Need need) {
  const toml::node* node = lookup(key, need, "a boolean (true or false)");
  if (!node) return false;
  if (!node->is_boolean()) {
    type_issue(key, *node, "a boolean (true or false)");
    return false;
  }
  out = node->as_boolean()->get();
  return true;
}

bool TableReader::read_numbers(std::string_view key, std::span<double> out, Need need) {
  const std::string expected = fmt::format("an array of {} numbers", out.size());
  const toml::node* node = lookup(key, need, expected);
  if (!node) return false;
  const toml::array* array = node->as_array();
  if (!array) {
    type_issue(key, *node, expected);
    return false;
  }
  if (array->size() != out.size()) {
    issue(key, fmt::format("expected {}, got {}", expected, array->size()));
    return false;
  }
  std::vector<double> values(out.size());
  bool ok = true;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = (*array)[i];
    const std::string element_path = index_path(child_path(path_, key), i);
    if (element.is_integer()) {
      values[i] = static_cast<double>(element.as_integer()->get());
    } else if (element.is_floating_point() && std::isfinite(element.as_floating_point()->get())) {
      values[i] = element.as_floating_point()->get();
    } else {
      issues_->push_back(make_issue(element_path, line_of_node(element),
                                    fmt::format("expected a finite number, got {}", describe(element))));
      ok = false;
    }
  }
  if (ok) std::copy(values.begin(), values.end(), out.begin());
  return ok;
}

bool TableReader::read_as_text(std::string_view key, std::string& out) {
  constexpr std::string_view kExpected = "a string, number or boolean";
  const toml::node* node = lookup(key, Need::optional, kExpected);
  if (!node) return false;
  switch (node->type()) {
    case toml::node_type::string: out = node->as_string()->get(); return true;
    case toml::node_type::integer: out = fmt::format("{}", node->as_integer()->get()); return true;
    case toml::node_type::floating_point: out = fmt::format("{}", node->as_floating_point()->get()); return true;
    case toml::node_type::boolean: out = node->as_boolean()->get() ? "true" : "false"; return true;
    default: type_issue(key, *node, kExpected); return false;
  }
}

std::optional<TableReader> TableReader::table(std::string_view key, Need need) {
  const toml::node* node = lookup(key, need, fmt::format("a table [{}]", child_path(path_, key)));
  if (!node) return std::nullopt;
  if (!node->is_table()) {
    type_issue(key, *node, fmt::format("a table [{}]", child_path(path_, key)));
    return std::nullopt;
  }
  return TableReader(*node->as_table(), child_path(path_, key), *issues_);
}

std::vector<TableReader> TableReader::array_of_tables(std::string_view key, Need need) {
  const std::string array_path = child_path(path_, key);
  const std::string expected = fmt::format("at least one [[{}]] entry", array_path);
  std::vector<TableReader> readers;
  const toml::node* node = lookup(key, need, expected);
  if (!node) return readers;
  const toml::array* array = node->as_array();
  if (!array) {
    type_issue(key, *node, fmt::format("an array of tables ([[{}]])", array_path));
    return readers;
  }
  if (array->empty() && need == Need::required) issue(key, fmt::format("expected {}, got none", expected));
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& element = (*array)[i];
    if (const toml::table* t = element.as_table()) {
      readers.emplace_back(*t, index_path(array_path, i), *issues_);
    } else {
      issues_->push_back(make_issue(index_path(array_path, i), line_of_node(element),
                                    fmt::format("expected a table, got {}", describe(element))));
    }
  }
  return readers;
}

std::vector<std::string> TableReader::keys() const {
  std::vector<std::string> out;
  for (auto&& [k, v] : *table_) out.emplace_back(k.str());
  return out;
}

void TableReader::report_unknown_keys() {
  for (auto&& [k, v] : *table_) {
    if (std::find(known_.begin(), known_.end(), k.str()) != known_.end()) continue;
    std::string message = "unknown key";
    if (auto suggestion = closest_match(k.str(), known_)) message += fmt::format(", did you mean \"{}\"?", *suggestion);
    message += fmt::format(" (allowed: {})", fmt::join(known_, ", "));
    issues_->push_back(make_issue(child_path(path_, k.str()), static_cast<int>(k.source().begin.line), std::move(message)));
  }
}

std::string unknown_word_message(std::string_view word, const std::vector<std::string>& allowed) {
  std::string message = fmt::format("\"{}\" must be one of {}", word, fmt::join(allowed, ", "));
  if (auto suggestion = closest_match(word, allowed)) message += fmt::format(", did you mean \"{}\"?", *suggestion);
  return message;
}

}  // namespace tomorig::config::detail
