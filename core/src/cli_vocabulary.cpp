#include "tomorig/core/cli_vocabulary.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <mutex>
#include <set>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "tomorig/core/error.h"

namespace tomorig::cli {
namespace {

constexpr const char* kDurationForm = "give a number with its unit: ns, us, ms or s (e.g. 80us, 1.5ms)";

std::optional<double> unit_ns(std::string_view unit) {
  if (unit == "ns") return 1.0;
  if (unit == "us" || unit == "\xC2\xB5s" || unit == "\xCE\xBCs") return 1e3;  // us, µs (micro sign, Greek mu)
  if (unit == "ms") return 1e6;
  if (unit == "s") return 1e9;
  return std::nullopt;
}

}  // namespace

double parse_duration_ns(std::string_view text, std::string_view option) {
  const auto fail = [&](const std::string& why) {
    return bad_input(fmt::format("{} '{}' is not valid: {}; {}", option, text, why, kDurationForm));
  };
  double value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || !std::isfinite(value)) throw fail("no number");
  std::string_view unit = text.substr(static_cast<std::size_t>(end - text.data()));
  while (!unit.empty() && unit.front() == ' ') unit.remove_prefix(1);
  if (unit.empty()) throw fail("the unit is missing");
  const std::optional<double> scale = unit_ns(unit);
  if (!scale) throw fail(fmt::format("unknown unit '{}'", unit));
  if (value < 0) throw fail("it must not be negative");
  return value * *scale;
}

bool warn_deprecated(std::string_view old_spelling, std::string_view use_instead) {
  static std::mutex mutex;
  static std::set<std::string, std::less<>> warned;
  const std::lock_guard lock(mutex);
  if (!warned.emplace(old_spelling).second) return false;
  spdlog::warn("{} is deprecated and will be removed in the next release; use {}", old_spelling, use_instead);
  return true;
}

void add_session_argument(CLI::App& cmd, std::string& session, const std::string& help, bool had_option) {
  cmd.add_option("session", session, help)->type_name("SESSION");
  if (had_option) add_deprecated_option(cmd, "--session", session, "the positional SESSION (tomorig " + cmd.get_name() + " SESSION.h5 ...)");
}

void require_session(const std::string& session, std::string_view command) {
  if (session.empty())
    throw bad_input(fmt::format("tomorig {}: no session given; name the session file first: tomorig {} SESSION.h5 ...",
                                command, command));
}

void add_dt_option(CLI::App& cmd, std::optional<double>& dt_ns, const std::string& help) {
  cmd.add_option_function<std::string>("--dt", [&dt_ns](const std::string& v) { dt_ns = parse_duration_ns(v, "--dt"); },
                                       help + " (with its unit: 80us, 1.5ms, 200ns)")
      ->type_name("DURATION");
  const auto legacy = [&](const char* name, double scale) {
    cmd.add_option_function<double>(
           name,
           [&dt_ns, name, scale](double v) {
             warn_deprecated(name, "--dt with a unit (e.g. --dt 80us)");
             dt_ns = v * scale;  // the command checks the value, as for --dt
           },
           "deprecated: use --dt")
        ->group("");
  };
  legacy("--dt-us", 1e3);
  legacy("--dt-ns", 1.0);
}

std::vector<std::string> apply_json_value_rule(std::vector<std::string> args) {
  const auto names_json_file = [](const std::string& a) {
    if (a == "-") return true;
    if (a.size() < 5) return false;
    std::string tail = a.substr(a.size() - 5);
    for (char& c : tail) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return tail == ".json";
  };
  for (std::size_t i = 0; i + 1 < args.size(); ++i) {
    if (args[i] == "--") break;
    if (args[i] != "--json") continue;
    const std::string& next = args[i + 1];
    if ((!next.empty() && next.front() == '-') || names_json_file(next)) continue;
    args.erase(args.begin() + static_cast<std::ptrdiff_t>(i));
    const auto end = std::find(args.begin(), args.end(), std::string("--"));
    args.insert(end, "--json");
    break;
  }
  return args;
}

}  // namespace tomorig::cli
