// The chain description: step names, parameter validation and the TOML reader. Every error
// names the key path and its line, and says what is allowed, so a hand-written chain file is
// fixed in one go.
#include "tomorig/processing/preprocess/chain_spec.h"

#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <set>
#include <sstream>
#include <utility>

#include <fmt/core.h>

#include "tomorig/config/toml_document.h"
#include "tomorig/core/error.h"

namespace tomorig::preprocess {
namespace {

constexpr std::array<std::pair<StepKind, std::string_view>, 10> kKindNames{{
    {StepKind::subtract_dark, "subtract_dark"},
    {StepKind::subtract_minimum, "subtract_minimum"},
    {StepKind::subtract_local_minimum, "subtract_local_minimum"},
    {StepKind::median, "median"},
    {StepKind::lowpass, "lowpass"},
    {StepKind::highpass, "highpass"},
    {StepKind::normalize, "normalize"},
    {StepKind::flat_field, "flat_field"},
    {StepKind::invert, "invert"},
    {StepKind::clip, "clip"},
}};

std::string kind_list() {
  std::string names;
  for (const auto& [kind, name] : kKindNames) names += (names.empty() ? "" : ", ") + std::string(name);
  return names;
}

// The keys each kind accepts besides "kind".
std::set<std::string> allowed_keys(StepKind kind) {
  switch (kind) {
    case StepKind::subtract_dark: return {"file", "level"};
    case StepKind::subtract_minimum: return {};
    case StepKind::subtract_local_minimum: return {"size"};
    case StepKind::median: return {"size"};
    case StepKind::lowpass:
    case StepKind::highpass: return {"sigma"};
    case StepKind::normalize: return {"by", "target", "size"};
    case StepKind::flat_field: return {"file"};
    case StepKind::invert: return {"max"};
    case StepKind::clip: return {"level", "sigmas", "subtract"};
  }
  return {};
}

std::string joined(const std::set<std::string>& keys) {
  if (keys.empty()) return "none";
  std::string s;
  for (const auto& k : keys) s += (s.empty() ? "" : ", ") + k;
  return s;
}

// Reads one step table; every failure names "<source>: <path>.<key> (line N)".
class StepReader {
 public:
  StepReader(const std::string& source, std::string path, config::TomlNode table)
      : source_(source), path_(std::move(path)), table_(table) {}

  [[noreturn]] void fail(const std::string& key, config::TomlNode node, const std::string& problem) const {
    const int line = node ? node.line() : table_.line();
    throw bad_input(fmt::format("{}: {}{} (line {}): {}", source_, path_, key.empty() ? "" : "." + key, line, problem));
  }

  bool has(const char* key) const { return table_.contains(key); }

  double number(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n.is_number()) fail(key, n, "must be a number");
    const double v = n.is_integer() ? static_cast<double>(*n.as_integer()) : *n.as_double();
    if (!std::isfinite(v)) fail(key, n, "must be a finite number");
    return v;
  }
  int integer(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n.is_integer()) fail(key, n, "must be an integer");
    const auto v = *n.as_integer();
    if (v < -1000000 || v > 1000000) fail(key, n, "is out of range");
    return static_cast<int>(v);
  }
  std::string string(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n.is_string()) fail(key, n, "must be a string");
    return *n.as_string();
  }
  bool boolean(const char* key) const {
    const config::TomlNode n = table_[key];
    if (!n.is_boolean()) fail(key, n, "must be true or false");
    return *n.as_bool();
  }
  config::TomlNode node(const char* key) const { return table_[key]; }

 private:
  const std::string& source_;
  std::string path_;
  config::TomlNode table_;
};

Step read_step(const StepReader& r, config::TomlNode table) {
  if (!r.has("kind")) r.fail("kind", {}, "is missing; one of: " + kind_list());
  const std::string kind_name = r.string("kind");
  std::optional<StepKind> kind;
  for (const auto& [k, name] : kKindNames)
    if (name == kind_name) kind = k;
  if (!kind) r.fail("kind", r.node("kind"), fmt::format("unknown step '{}'; one of: {}", kind_name, kind_list()));

  const auto allowed = allowed_keys(*kind);
  for (const auto& [k, value] : table.entries()) {
    if (k != "kind" && !allowed.count(k))
      r.fail(k, value, fmt::format("is not a parameter of '{}'; allowed: {}", kind_name, joined(allowed)));
  }

  Step step;
  step.kind = *kind;
  switch (*kind) {
    case StepKind::subtract_dark:
      if (r.has("file") == r.has("level"))
        r.fail("", {}, "subtract_dark needs exactly one of 'file' (a session of dark frames) or 'level' (counts)");
      if (r.has("file")) step.file = r.string("file");
      if (r.has("level")) step.level = r.number("level");
      break;
    case StepKind::subtract_local_minimum:
      step.size = r.has("size") ? r.integer("size") : 5;
      break;
    case StepKind::median:
      step.size = r.has("size") ? r.integer("size") : 3;
      break;
    case StepKind::lowpass:
    case StepKind::highpass:
      step.sigma = r.has("sigma") ? r.number("sigma") : 1.0;
      break;
    case StepKind::normalize:
      if (r.has("by")) {
        const std::string by = r.string("by");
        if (by == "mean") step.by = NormalizeBy::mean;
        else if (by == "average_image") step.by = NormalizeBy::average_image;
        else if (by == "local") step.by = NormalizeBy::local;
        else r.fail("by", r.node("by"), fmt::format("'{}' is not allowed; use \"mean\", \"average_image\" or \"local\"", by));
      }
      step.size = kLocalNormalizeTile;
      if (r.has("size")) {
        if (step.by != NormalizeBy::local) r.fail("size", r.node("size"), "applies to by = \"local\" only (its tile size)");
        step.size = r.integer("size");
      }
      if (r.has("target")) step.target = r.number("target");
      break;
    case StepKind::flat_field:
      if (!r.has("file")) r.fail("file", {}, "is missing: the session file of bright-field frames");
      step.file = r.string("file");
      break;
    case StepKind::invert:
      if (r.has("max")) step.max = r.number("max");
      break;
    case StepKind::clip:
      if (r.has("level") == r.has("sigmas"))
        r.fail("", {}, "clip needs exactly one of 'level' (counts) or 'sigmas' (k of the background sigma)");
      if (r.has("level")) step.level = r.number("level");
      if (r.has("sigmas")) {
        step.use_sigmas = true;
        step.sigmas = r.number("sigmas");
      }
      if (r.has("subtract")) step.subtract = r.boolean("subtract");
      break;
    case StepKind::subtract_minimum: break;
  }
  return step;
}

}  // namespace

std::string_view to_string(StepKind kind) {
  for (const auto& [k, name] : kKindNames)
    if (k == kind) return name;
  return "unknown";
}

bool needs_sequence_image(const Step& step) {
  return step.kind == StepKind::subtract_minimum ||
         (step.kind == StepKind::normalize && step.by == NormalizeBy::average_image);
}

bool needs_reference_image(const Step& step) {
  return step.kind == StepKind::flat_field || (step.kind == StepKind::subtract_dark && !step.file.empty());
}

void validate(const Step& step, std::size_t index) {
  const auto fail = [&](const char* parameter, const std::string& problem) {
    throw bad_input(fmt::format("preprocess step {} ({}): {} {}", index, to_string(step.kind), parameter, problem));
  };
  switch (step.kind) {
    case StepKind::subtract_dark:
      if (step.file.empty() && step.level < 0) fail("level", fmt::format("must be >= 0, got {}", step.level));
      break;
    case StepKind::subtract_local_minimum:
      if (step.size < 2 || step.size > 101)
        fail("size", fmt::format("must be an integer from 2 to 101, got {}", step.size));
      break;
    case StepKind::median:
      if (step.size != 3 && step.size != 5) fail("size", fmt::format("must be 3 or 5, got {}", step.size));
      break;
    case StepKind::lowpass:
    case StepKind::highpass:
      if (!(step.sigma > 0 && step.sigma <= 50))
        fail("sigma", fmt::format("must be in (0, 50] pixels, got {}", step.sigma));
      break;
    case StepKind::normalize:
      if (!(step.target > 0)) fail("target", fmt::format("must be > 0, got {}", step.target));
      if (step.by == NormalizeBy::local && (step.size < 8 || step.size > 1024))
        fail("size", fmt::format("must be an integer from 8 to 1024 pixels, got {}", step.size));
      break;
    case StepKind::flat_field:
      if (step.file.empty()) fail("file", "is empty: give the session file of bright-field frames");
      break;
    case StepKind::invert:
      if (!(step.max > 0)) fail("max", fmt::format("must be > 0, got {}", step.max));
      break;
    case StepKind::clip:
      if (step.use_sigmas && !(step.sigmas >= 0 && step.sigmas <= 100))
        fail("sigmas", fmt::format("must be in [0, 100], got {}", step.sigmas));
      if (!step.use_sigmas && step.level < 0) fail("level", fmt::format("must be >= 0, got {}", step.level));
      break;
    case StepKind::subtract_minimum: break;
  }
}

ChainSpec parse_chain(std::string_view toml_text, const std::string& source) {
  std::optional<config::TomlDocument> doc;
  try {
    doc = config::TomlDocument::parse(toml_text, source);
  } catch (const config::TomlSyntaxError& e) {
    throw bad_input(fmt::format("{}: line {}: {}", source, e.line(), e.description()));
  }
  const auto top_fail = [&](const std::string& key, config::TomlNode n, const std::string& problem) {
    throw bad_input(fmt::format("{}: {} (line {}): {}", source, key, n.line(), problem));
  };
  const config::TomlNode root = doc->root();
  for (const auto& [key, value] : root.entries())
    if (key != "preprocess") top_fail(key, value, "is not allowed; the file holds [[preprocess.steps]] only");
  const config::TomlNode pre = root["preprocess"];
  if (!pre.is_table()) throw bad_input(fmt::format("{}: no [[preprocess.steps]]: give at least one step", source));
  for (const auto& [key, value] : pre.entries())
    if (key != "steps")
      top_fail("preprocess." + key, value, "is not allowed; only preprocess.steps");
  const config::TomlNode steps = pre["steps"];
  if (!steps.is_array() || steps.size() == 0) throw bad_input(fmt::format("{}: preprocess.steps must be a non-empty array of tables ([[preprocess.steps]])", source));

  ChainSpec spec;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const std::string path = fmt::format("preprocess.steps[{}]", i);
    const config::TomlNode t = steps[i];
    if (!t.is_table()) top_fail(path, t, "must be a table with a 'kind'");
    const StepReader reader(source, path, t);
    Step step = read_step(reader, t);
    try {
      validate(step, i);
    } catch (const Error& e) {
      // Re-say the problem with the key path and line of the file.
      throw bad_input(fmt::format("{}: {} (line {}): {}", source, path, t.line(), e.what()));
    }
    spec.steps.push_back(std::move(step));
  }
  return spec;
}

ChainSpec read_chain_file(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in)
    throw bad_input(fmt::format("cannot read the chain file '{}': check the path, or name a preset (shadow-a, "
                                "shadow-b, shadow-detect)",
                                path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return parse_chain(text.str(), path.string());
}

}  // namespace tomorig::preprocess
