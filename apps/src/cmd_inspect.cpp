// tomorig inspect FILE [--json]: what a session holds, for people (text) and scripts (JSON).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/session_summary.h"

namespace tomorig::app {
namespace {

struct InspectArgs {
  std::string file;
  bool json = false;
};

std::string human_size(std::uintmax_t bytes) {
  const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  double value = static_cast<double>(bytes);
  int unit = 0;
  while (value >= 1024.0 && unit < 4) {
    value /= 1024.0;
    ++unit;
  }
  return unit == 0 ? fmt::format("{} B", bytes) : fmt::format("{:.1f} {}", value, units[unit]);
}

std::string microseconds(std::int64_t ns) { return fmt::format("{:g} us", static_cast<double>(ns) * 1e-3); }

nlohmann::json to_json(const storage::SessionSummary& s) {
  using nlohmann::json;
  json cameras = json::array();
  for (const auto& c : s.cameras)
    cameras.push_back({{"id", c.id},
                       {"width", c.width},
                       {"height", c.height},
                       {"pixel_format", std::string(to_string(c.pixel_format))},
                       {"pixel_pitch_um", c.pixel_pitch_um}});
  json j = {
      {"file", s.path.string()},
      {"file_size_bytes", s.file_size_bytes},
      {"format", "tomorig-session"},
      {"format_version", s.format_version},
      {"software_version", s.software_version},
      {"created_utc", s.created_utc},
      {"compression", std::string(to_string(s.compression))},
      {"cameras", cameras},
      {"sets", s.sets},
      {"missing_frames", s.missing_frames},
      {"incomplete_sets", s.incomplete_sets},
      {"time_span_s", s.time_span_s},
      {"truth", s.truth},
  };
  // Values that do not exist for an empty session are null rather than a misleading 0.
  j["dt_ns"] = s.sets == 0 ? json(nullptr) : json{{"min", s.dt_ns_min}, {"max", s.dt_ns_max}};
  j["trigger_index"] =
      s.sets == 0 ? json(nullptr) : json{{"first", s.first_trigger_index}, {"last", s.last_trigger_index}};
  if (s.truth) j["truth_info"] = {{"case", s.truth_case}, {"flow", s.truth_flow}, {"sets", s.truth_sets}};
  return j;
}

void print_text(const storage::SessionSummary& s) {
  fmt::print("session      {} ({})\n", s.path.string(), human_size(s.file_size_bytes));
  fmt::print("format       tomorig-session v{}, written by tomorig {} at {}\n", s.format_version,
             s.software_version.empty() ? "(unknown)" : s.software_version,
             s.created_utc.empty() ? "(unknown time)" : s.created_utc);
  fmt::print("compression  {}\n", to_string(s.compression));
  fmt::print("cameras      {}\n", s.cameras.size());
  for (const auto& c : s.cameras)
    fmt::print("  {:<10} {} x {}  {:<6}  pixel pitch {}\n", c.id, c.width, c.height, to_string(c.pixel_format),
               c.pixel_pitch_um > 0 ? fmt::format("{:g} um", c.pixel_pitch_um) : std::string("unknown"));
  if (s.sets == 0) {
    fmt::print("sets         0\n");
  } else {
    fmt::print("sets         {} (trigger index {} to {})\n", s.sets, s.first_trigger_index, s.last_trigger_index);
    fmt::print("time span    {:.3f} s\n", s.time_span_s);
    if (s.dt_ns_min == s.dt_ns_max)
      fmt::print("dt           {}\n", microseconds(s.dt_ns_min));
    else
      fmt::print("dt           {} to {}\n", microseconds(s.dt_ns_min), microseconds(s.dt_ns_max));
  }
  fmt::print("missing      {} frame{} in {} incomplete set{}\n", s.missing_frames, s.missing_frames == 1 ? "" : "s",
             s.incomplete_sets, s.incomplete_sets == 1 ? "" : "s");
  if (s.truth)
    fmt::print("truth        yes: case {}, flow {}, {} set{} with particles\n", s.truth_case, s.truth_flow,
               s.truth_sets, s.truth_sets == 1 ? "" : "s");
  else
    fmt::print("truth        no\n");
}

}  // namespace

void add_inspect_command(CLI::App& root) {
  auto args = std::make_shared<InspectArgs>();
  CLI::App* cmd = root.add_subcommand("inspect", "Summarise a session file: cameras, sets, timing, missing frames");
  cmd->add_option("file", args->file, "Session file (.h5)")->required();
  cmd->add_flag("--json", args->json, "Print one JSON object instead of text");
  cmd->callback([args] {
    const storage::SessionReader reader(args->file);  // throws bad_input for bad files
    const storage::SessionSummary summary = storage::summarize(reader);
    if (args->json)
      fmt::print("{}\n", to_json(summary).dump(2));
    else
      print_text(summary);
  });
}

}  // namespace tomorig::app
