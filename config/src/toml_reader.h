#pragma once
// A typed, checking view of one TOML table. Every read names the key it expects, so that
//  - a value of the wrong type, out of range or missing becomes a ConfigIssue with the key path
//    and line, and reading goes on (all issues are collected, not just the first);
//  - after the reads, every key nobody asked for is reported as unknown, with the closest
//    known key as a suggestion. The schema is thus exactly the set of reads in decode_*.cpp.
// A read leaves `out` (holding its default) untouched unless the value is present and valid.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "rules.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config::detail {

enum class Need { optional, required };

class TableReader {
 public:
  // `path` is the table's key path ("" for the document root).
  TableReader(const toml::table& table, std::string path, std::vector<ConfigIssue>& issues);

  const std::string& path() const { return path_; }
  int line() const { return line_; }  // the table's header line; 0 for the root
  // Line of `key`'s value, or the table's line when the key is absent.
  int line_of(std::string_view key) const;
  bool has(std::string_view key) const { return table_->contains(key); }

  bool read(std::string_view key, std::string& out, Need need = Need::optional, const Rule<std::string>& rule = {});
  bool read(std::string_view key, int& out, Need need = Need::optional, const Rule<int>& rule = {});
  bool read(std::string_view key, std::uint64_t& out, Need need = Need::optional, const Rule<std::uint64_t>& rule = {});
  // Numbers: a TOML float or integer; must be finite.
  bool read(std::string_view key, double& out, Need need = Need::optional, const Rule<double>& rule = {});
  bool read(std::string_view key, bool& out, Need need = Need::optional);
  // An array of exactly out.size() numbers, e.g. origin_mm = [0, 0, 0].
  bool read_numbers(std::string_view key, std::span<double> out, Need need = Need::optional);
  // A string naming a value of E (rig_vocabulary.h); an unknown word's message names the key,
  // the word, the allowed words and the closest one.
  template <HasVocabulary E>
  bool read_choice(std::string_view key, E& out, Need need = Need::optional);
  // A string, number or boolean as text (GenICam features are passed on verbatim).
  bool read_as_text(std::string_view key, std::string& out);

  std::optional<TableReader> table(std::string_view key, Need need = Need::optional);
  // [[key]] entries (or an array of inline tables); required means at least one entry.
  std::vector<TableReader> array_of_tables(std::string_view key, Need need = Need::optional);

  std::vector<std::string> keys() const;  // every key of the table as written in the file

  // Reports each key of the table that no read asked for. Call once, after all reads.
  void report_unknown_keys();

  // An issue about `key` (a key of this table), at its line.
  void issue(std::string_view key, std::string message);

 private:
  const toml::node* lookup(std::string_view key, Need need, std::string_view expected);
  void type_issue(std::string_view key, const toml::node& node, std::string_view expected);

  const toml::table* table_;
  std::string path_;
  std::vector<ConfigIssue>* issues_;
  int line_ = 0;
  std::vector<std::string> known_;  // keys asked for, in schema order (for "allowed: ...")
};

// For cross-key checks: a key that is absent keeps its (valid) default, one that is present
// counts only if its read succeeded. Usage: valid_or_absent(r, "dt_us", r.read("dt_us", ...)).
inline bool valid_or_absent(const TableReader& r, std::string_view key, bool read_ok) {
  return read_ok || !r.has(key);
}

// "\"third\" must be one of first, second, both[, did you mean \"both\"?]"
std::string unknown_word_message(std::string_view word, const std::vector<std::string>& allowed);

template <HasVocabulary E>
bool TableReader::read_choice(std::string_view key, E& out, Need need) {
  std::string name;
  if (!read(key, name, need)) return false;
  if (const auto value = parse<E>(name)) {
    out = *value;
    return true;
  }
  std::vector<std::string> allowed;
  for (const auto& w : Vocabulary<E>::words) allowed.emplace_back(w.name);
  issue(key, unknown_word_message(name, allowed));
  return false;
}

}  // namespace tomorig::config::detail
