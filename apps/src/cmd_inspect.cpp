// tomorig inspect FILE [--json]: what a session holds, for people (text) and scripts (JSON).
#include <filesystem>
#include <memory>
#include <vector>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/quicklook_history.h"
#include "tomorig/processing/quicklook/display.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/session_summary.h"

namespace tomorig::app {
namespace {

struct InspectArgs {
  std::string file;
  JsonOutput json;
  std::string png_folder;
  std::uint64_t set = 0;
};

// Quick-looks of one set: every present frame, stretched to 8 bits, as
// <folder>/<camera>_set<k>_<A|B>.png. Returns the files written.
std::vector<std::filesystem::path> write_quicklooks(const storage::SessionReader& reader, std::uint64_t set_index,
                                                    const std::filesystem::path& folder) {
  if (set_index >= reader.set_count())
    throw bad_input(fmt::format("--set {} is out of range: session '{}' has {} sets", set_index,
                                reader.path().string(), reader.set_count()));
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder))
    throw bad_input(fmt::format("cannot create the quick-look folder '{}': {}; choose another --png", folder.string(),
                                ec ? ec.message() : "it is not a folder"));
  const FrameSet set = reader.read_set(set_index);
  std::vector<std::filesystem::path> written;
  for (const CameraFrames& camera : set.cameras)
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      if (!camera[e].present()) continue;
      const auto file = folder / fmt::format("{}_set{}_{}.png", camera.camera_id, set_index, e == Exposure::A ? "A" : "B");
      storage::write_png(file, quicklook::stretch_to_8bit(camera[e].image));
      written.push_back(file);
    }
  return written;
}

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
      {"recording_complete", s.recording_complete},
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
             s.software_version.empty() ? "(unknown)" : printable(s.software_version),
             s.created_utc.empty() ? "(unknown time)" : printable(s.created_utc));
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
  if (!s.recording_complete)
    fmt::print("recording    not finished: still being written, or interrupted; the {} sets shown are complete\n",
               s.sets);
  fmt::print("missing      {} frame{} in {} incomplete set{}\n", s.missing_frames, s.missing_frames == 1 ? "" : "s",
             s.incomplete_sets, s.incomplete_sets == 1 ? "" : "s");
  if (s.truth)
    fmt::print("truth        yes: case {}, flow {}, {} set{} with particles\n", printable(s.truth_case), printable(s.truth_flow),
               s.truth_sets, s.truth_sets == 1 ? "" : "s");
  else
    fmt::print("truth        no\n");
}

}  // namespace

void add_inspect_command(CLI::App& root) {
  auto args = std::make_shared<InspectArgs>();
  CLI::App* cmd = root.add_subcommand("inspect", "Summarise a session file: cameras, sets, timing, missing frames, quick-look history");
  cmd->add_option("session", args->file, "Session file (.h5)")->required()->type_name("SESSION");
  add_json_flag(*cmd, args->json);
  cmd->add_option("--png", args->png_folder,
                  "Also write 8-bit PNG quick-looks of one set's frames into this folder (created if needed)");
  cmd->add_option("--set", args->set, "Set for --png, 0-based")->capture_default_str();
  cmd->callback([args] {
    const storage::SessionReader reader(args->file);  // throws bad_input for bad files
    const storage::SessionSummary summary = storage::summarize(reader);
    const pipeline::QuickLookHistory history = pipeline::quicklook_history(reader);
    std::vector<std::filesystem::path> pngs;
    if (!args->png_folder.empty()) pngs = write_quicklooks(reader, args->set, args->png_folder);
    if (args->json.wanted()) {
      nlohmann::json j = json_summary("inspect");
      j.update(to_json(summary));
      j["quicklook"] = pipeline::to_json(history);
      if (!args->png_folder.empty()) {
        j["quicklooks"] = nlohmann::json::array();
        for (const auto& p : pngs) j["quicklooks"].push_back(p.string());
      }
      emit_json(args->json, j);
    }
    if (!args->json.to_stdout()) {
      print_text(summary);
      fmt::print("{}", history.sets > 0 ? pipeline::history_text(history)
                                        : std::string("quick-look   none stored (recorded without a quick-look stage)\n"));
      for (const auto& p : pngs) fmt::print("quick-look   {}\n", p.string());
    }
  });
}

}  // namespace tomorig::app
