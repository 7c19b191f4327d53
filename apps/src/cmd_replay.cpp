// tomorig replay: publishes a recorded session's FrameSets on the lossless stream (PUSH), as
// an acquisition process would (rig::SessionReplay), so that a recorder or a processing back end
// can be run and tested without a rig. Replay binds by default and the receiver (tomorig
// record) connects. --preview / --http add the quick-look and its dashboard on the sets sent.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "commands.h"
#include "http_options.h"
#include "json_summary.h"
#include "tomorig/core/error.h"
#include "tomorig/dashboard/live_dashboard.h"
#include "tomorig/dashboard/session_view.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/pipeline/stage_chain.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/rig/session_replay.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/preview.h"

namespace tomorig::app {
namespace {

struct ReplayOptions {
  rig::SessionReplayOptions replay;
  std::string file;
  JsonOutput json;
  std::vector<std::string> preview;  // --preview [ENDPOINT]
  bool preview_given = false;
  HttpChoices http;  // --http: the dashboard of the replay, fed by its quick-look
  bool http_given = false;
};

// --preview: the quick-look stage on every set sent, publishing for `tomorig preview`. It skips
// sets to stay current, so it never holds the replay back. --http turns it on at the default
// endpoint if --preview did not, and serves the dashboard on it, subscribed like a separate
// `tomorig preview --http` would be.
struct ReplayQuicklook {
  std::optional<pipeline::StageChain> chain;
  std::optional<dashboard::LiveDashboard> board;

  ReplayQuicklook(const ReplayOptions& opt, const storage::SessionReader& session) {
    if (!opt.preview_given && !opt.http_given) return;
    const std::string endpoint = pipeline::preview_endpoint(opt.preview);
    const std::optional<config::RigConfig> rig = dashboard::session_rig(session);
    const std::optional<dashboard::DashboardServerOptions> http =
        opt.http_given ? std::optional(http_server_options(opt.http, rig ? &rig->dashboard : nullptr)) : std::nullopt;
    chain = pipeline::make_chain(rig::all_stages(), {pipeline::quicklook_stage_spec(endpoint, {})});
    chain->begin(pipeline::describe_session(session));
    fmt::print(stderr, "replay: quick-look results on {} (watch: tomorig preview --from {})\n", endpoint, endpoint);
    if (!http) return;
    board.emplace(dashboard::InfoSource{.mode = "live", .source = opt.file, .rig = rig ? &*rig : nullptr},
                  dashboard::LiveFeedOptions{
                      .preview_endpoint = endpoint,
                      .notice = [](const std::string& text) { fmt::print(stderr, "replay: {}\n", text); }},
                  *http);
    fmt::print(stderr, "replay: dashboard on {}\n", board->url());
  }
  void print_reports() {
    if (!chain) return;
    for (const pipeline::StageReport& r : chain->end())
      fmt::print(stderr, "replay: stage {}\nreplay: {}\n", r.brief(), pipeline::quicklook_report_text(r));
  }
};

void replay(ReplayOptions& opt) {
  opt.replay.session = opt.file;
  opt.replay.status_line = true;
  rig::SessionReplay replay(opt.replay);
  ReplayQuicklook quicklook(opt, replay.session());
  const rig::StopSignalGuard stop;
  const rig::SetRange range = replay.range();
  const rig::SessionReplayReport report = replay.run({
      .sending =
          [&](const std::string& endpoint) {
            // The first line names the real endpoint (a "*" port resolved), for scripts and tests.
            fmt::print(stderr, "replay: {} {}, sets {} to {} of {}, rate {}{}\n",
                       opt.replay.connect ? "connected to" : "sending on", endpoint, range.first, range.last - 1,
                       opt.file, opt.replay.rate, opt.replay.loop ? ", looping" : "");
            std::fflush(stderr);
          },
      .sent = [&](const FrameSet& set) { if (quicklook.chain) quicklook.chain->push(set); },
      .notice = [](const std::string& text) { fmt::print(stderr, "replay: {}\n", text); },
      .stop = &stop,
  });
  quicklook.print_reports();
  if (!report.failure.empty()) throw runtime_error(report.failure);
  if (!opt.json.to_stdout()) fmt::print("{}\n", report.brief());
  nlohmann::json j = json_summary("replay");
  j["session"] = opt.file;
  j["endpoint"] = report.endpoint;
  j[json_key::kSets] = report.sets_sent;
  j["bytes"] = report.bytes_sent;
  j["blocked_sends"] = report.blocked_sets;
  j["stopped_by"] = report.stopped_by;
  emit_json(opt.json, j);
}

}  // namespace

void add_replay_command(CLI::App& root) {
  auto opt = std::make_shared<ReplayOptions>();
  CLI::App* cmd = root.add_subcommand(
      "replay", "Publish a session's frame sets on the lossless stream (binds; 'tomorig record' connects)");
  cmd->add_option("file", opt->file, "Session file (.h5) to replay")->required();
  cmd->add_option("--to", opt->replay.to,
                  "Stream endpoint; replay binds it (loopback only unless --allow-remote). A port * binds any "
                  "free port, printed on stderr")
      ->capture_default_str();
  cmd->add_flag("--connect", opt->replay.connect, "Connect to a receiver that binds (e.g. 'tomorig record --bind')");
  cmd->add_flag("--allow-remote", opt->replay.allow_remote, "Allow binding to a non-loopback address (needs --token)");
  cmd->add_option("--token", opt->replay.token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("--rate", opt->replay.rate, "recorded (trigger timestamps) | max | a rate in Hz")->capture_default_str();
  cmd->add_flag("--loop", opt->replay.loop, "Start over after the last set, until Ctrl-C");
  cmd->add_option("--sets", opt->replay.sets, "Sets to send: A:B (A to B-1), A:, :B or A");
  cmd->add_option("--timeout", opt->replay.timeout_s, "Seconds a send may wait for the receiver before giving up")
      ->capture_default_str();
  cmd->add_option("--wait", opt->replay.wait_s,
                  "Seconds to wait for a receiver to take the session start, the first message")->capture_default_str();
  cmd->add_option("--preview", opt->preview,
                  fmt::format("Also run the quick-look on the sets sent and publish it here for 'tomorig preview'; "
                              "without a value {}",
                              stream::kDefaultPreviewEndpoint))
      ->expected(0, 1);
  add_http_options(*cmd, opt->http);
  add_json_flag(*cmd, opt->json);
  cmd->callback([opt, cmd] {
    opt->preview_given = cmd->count("--preview") > 0;
    opt->http_given = opt->http.given(*cmd);
    replay(*opt);
  });
}

}  // namespace tomorig::app
