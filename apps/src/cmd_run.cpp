// tomorig run: the main job. Trigger device, cameras and recorder in one process
// (rig::RigRunner); with no arguments it runs the embedded simulated 4-camera tpiv-thesis rig.
#include <ctime>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "commands.h"
#include "json_summary.h"
#include "http_options.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/dashboard/live_dashboard.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/stream/preview.h"
#include "tomorig/rig/rig_run_options.h"
#include "tomorig/rig/rig_runner.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::app {
namespace {

struct RunArgs {
  rig::RigRunChoices rig;
  std::string out;
  std::string compression = "none";
  rig::RecorderOptions recorder;  // overwrite and disk_reserve_mb bound directly
  std::vector<std::string> stages;
  JsonOutput json;
  std::vector<std::string> preview;  // --preview [ENDPOINT]: given with or without a value
  bool preview_given = false;
  HttpChoices http;  // --http: the dashboard, fed by the run's quick-look and status streams
  bool http_given = false;
};

std::filesystem::path default_output_path() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc);
  return std::filesystem::path("runs") / fmt::format("session-{}.h5", stamp);
}

void run(const RunArgs& args) {
  const config::RigConfig rig = rig::load_rig(args.rig);
  rig::RigRunOptions options;
  options.recorder = args.recorder;
  options.recorder.compression = rig::parse_compression_option(args.compression);
  options.recorder.out = args.out.empty() ? default_output_path() : std::filesystem::path(args.out);
  options.acquisition = rig::rig_acquisition_options(rig, args.rig);
  options.status_endpoint = args.rig.status;
  options.notice = [](const std::string& text) { fmt::print(stderr, "run: {}\n", text); };
  for (const std::string& text : args.stages) options.stages.push_back(pipeline::parse_stage_spec(text));
  // The dashboard shows the quick-look: --http turns it on at the default endpoint if --preview did not.
  const std::string preview =
      args.preview_given || args.http_given ? pipeline::preview_endpoint(args.preview) : std::string();
  const std::optional<dashboard::DashboardServerOptions> http =
      args.http_given ? std::optional(http_server_options(args.http, &rig.dashboard)) : std::nullopt;
  if (!preview.empty()) options.stages.push_back(pipeline::quicklook_stage_spec(preview, options.stages));

  // Builds, configures and arms everything: a bad rig or output fails here, before a file exists.
  rig::RigRunner runner(rig, options);
  // With --json on stdout the header goes to stderr, so that stdout is the JSON object alone.
  fmt::print(args.json.to_stdout() ? stderr : stdout, "tomorig run: rig '{}', {} cameras, {}{}\n", rig.name, rig.cameras.size(),
             rig::run_length_text(options.acquisition),
             rig.simulation ? (rig.simulation->case_name == "spray-thesis" ? fmt::format(", case spray-thesis ({})", config::to_string(rig.simulation->spray)) : fmt::format(", case {} at {} ppp", rig.simulation->case_name, rig.simulation->ppp))
                            : std::string());
  std::fflush(stdout);
  if (!runner.status_endpoint().empty()) fmt::print(stderr, "run: status JSON on {}\n", runner.status_endpoint());
  if (!preview.empty()) fmt::print(stderr, "run: quick-look results on {} (watch: tomorig preview --from {})\n", preview, preview);
  // The dashboard subscribes to the run's own quick-look and status streams, as a separate
  // `tomorig preview --http` would, so it never holds the recorder up.
  std::optional<dashboard::LiveDashboard> board;
  if (http) {
    board.emplace(dashboard::InfoSource{.mode = "live", .source = rig.name, .rig = &rig},
                  dashboard::LiveFeedOptions{
                      .preview_endpoint = preview,
                      .status_endpoint = runner.status_endpoint(),
                      .notice = [](const std::string& text) { fmt::print(stderr, "run: {}\n", text); }},
                  *http);
    fmt::print(stderr, "run: dashboard on {}\n", board->url());
  }
  std::fflush(stderr);

  // Ctrl-C ends the run between sets: acquisition stops, the sets already taken are recorded,
  // and the file is closed complete and valid. A second Ctrl-C quits at once.
  const rig::StopSignalGuard stop;
  const rig::RigRunReport report = runner.run([&](const rig::RecorderReport&) { return stop.stop_requested(); });
  const std::string out = report.recording.out.string();
  if (!args.json.to_stdout()) fmt::print("{}\nnext: tomorig inspect {}\n", report.brief(), out);
  nlohmann::json j = json_summary("run");
  j[json_key::kOut] = out;
  j[json_key::kSets] = report.recording.written;
  j[json_key::kCameras] = report.cameras;
  j[json_key::kSeconds] = report.seconds;
  j["frames_lost"] = report.frames_lost;
  j["incomplete_sets"] = report.incomplete_sets;
  j["stopped"] = report.stopped;
  j["failure"] = report.failure;
  j["bytes"] = report.file_bytes;
  emit_json(args.json, j);
  for (const pipeline::StageReport& stage : report.stages) {
    fmt::print(stderr, "run: stage {}\n", stage.brief());
    if (const std::string text = pipeline::quicklook_report_text(stage); !text.empty()) fmt::print(stderr, "run: {}\n", text);
  }
  if (!report.recording.disk_full.empty())
    throw runtime_error(fmt::format("recording stopped: {}; {} is complete with {} sets", report.recording.disk_full,
                                    out, report.recording.written));
  if (!report.failure.empty())
    throw runtime_error(fmt::format("{}; {} is complete with {} sets", report.failure, out, report.recording.written));
  if (report.stopped)
    fmt::print(stderr, "stopped by {} after {} sets; the session is complete\n", stop.signal_name(),
               report.recording.written);
  // Every set flagged is a run that did not work, whatever was written (a wrong frame_mode,
  // cameras not answering the trigger): it must not look like success. Free-running cameras
  // make no set complete by design and are warned about on every status line instead.
  bool free_running = false;
  for (const auto& cam : rig.cameras) free_running |= cam.frame_mode == config::FrameMode::free_run;
  if (report.recording.written > 0 && report.incomplete_sets == report.recording.written && !free_running &&
      !report.stopped)
    throw runtime_error(fmt::format("none of the {} sets is complete ({} lost frames); {} keeps them, flagged. Check "
                                    "the cameras' frame_mode and the messages above",
                                    report.recording.written, report.frames_lost, out));
}

}  // namespace

void add_run_command(CLI::App& root) {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = root.add_subcommand(
      "run", "Run the rig: trigger, acquire and record a session (default: the embedded simulated "
             "4-camera tpiv-thesis rig)");
  rig::add_rig_run_options(*cmd, args->rig, "Record");
  cmd->add_option("-o,--out", args->out, "Session file to write; default: runs/session-<UTC time>.h5");
  cmd->add_option("--compression", args->compression, "Frame compression: none | bitshuffle-lz4");
  cmd->add_flag("--overwrite", args->recorder.overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", args->recorder.disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_option("--stage", args->stages,
                  "Also feed every recorded set to this stage, TYPE[:key=value,...] (repeatable; tomorig stages "
                  "lists them)");
  cmd->add_option("--preview", args->preview,
                  fmt::format("Run the quick-look (statistics, dt check, preview volume, drift alarm) on the recorded "
                              "sets and publish it here for 'tomorig preview'; without a value {}",
                              stream::kDefaultPreviewEndpoint))
      ->expected(0, 1);
  add_http_options(*cmd, args->http);
  add_json_flag(*cmd, args->json);
  cmd->callback([args, cmd] {
    args->preview_given = cmd->count("--preview") > 0;
    args->http_given = args->http.given(*cmd);
    run(*args);
  });
}

}  // namespace tomorig::app
