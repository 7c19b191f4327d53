// tomorig preview: watches the quick-look results a running rig (tomorig run --preview) or a
// replay (tomorig replay --preview) publishes. A terminal view refreshed in place, plain lines
// when stdout is not a terminal, one JSON line per set with --json, snapshots with --png; with
// --http the operator's dashboard in a browser instead (docs/dashboard.md), live or, with
// --session, a recorded run's quick-look history.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "tomorig/core/cli_vocabulary.h"
#include "http_options.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/dashboard/dashboard_server.h"
#include "tomorig/dashboard/live_dashboard.h"
#include "tomorig/dashboard/session_view.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/pipeline/quicklook_view.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/stream/preview.h"

namespace tomorig::app {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

struct PreviewArgs {
  std::string from = stream::kDefaultPreviewEndpoint;
  pipeline::QuickLookViewOptions view;
  std::string png;
  std::uint64_t count = 0;  // stop after this many sets; 0: until Ctrl-C
  double timeout_s = 0;     // give up after this long without a message; 0: wait for ever
  HttpChoices http;
  bool http_given = false;
  std::string status;      // --status: the run's status stream, for the dashboard
  std::string config_path; // --config: the rig, for the dashboard's trigger plan and targets
  std::string session;     // --session: a recorded run's history on the dashboard
};

// --http: serve the dashboard until Ctrl-C, fed live by the streams or by a session file.
void serve_dashboard(const PreviewArgs& args) {
  std::optional<config::RigConfig> rig;
  if (!args.config_path.empty()) rig = config::load_rig_config(args.config_path);
  const dashboard::DashboardServerOptions server_options = http_server_options(args.http, rig ? &rig->dashboard : nullptr);
  const rig::StopSignalGuard stop;
  if (!args.session.empty()) {
    dashboard::DashboardState state;
    const storage::SessionReader session(args.session);  // before any thread starts (see SessionReader)
    dashboard::show_session(state, session);
    dashboard::DashboardServer server(state, server_options);
    fmt::print(stderr, "preview: dashboard on {} showing {} (Ctrl-C ends)\n", server.url(), args.session);
    std::fflush(stderr);
    while (!stop.wait_for(std::chrono::seconds(1))) {
    }
    server.stop();
    fmt::print(stderr, "preview: dashboard stopped by {} after {} quick-look messages\n", stop.signal_name(),
               state.messages());
    return;
  }
  dashboard::LiveDashboard board(
      {.mode = "live", .source = args.from, .rig = rig ? &*rig : nullptr},
      {.preview_endpoint = args.from,
       .status_endpoint = args.status,
       .notice = [](const std::string& text) { fmt::print(stderr, "preview: {}\n", text); }},
      server_options);
  fmt::print(stderr, "preview: dashboard on {} showing {} (Ctrl-C ends)\n", board.url(), args.from);
  std::fflush(stderr);
  while (!stop.wait_for(std::chrono::seconds(1))) {
  }
  board.stop();
  fmt::print(stderr, "preview: dashboard stopped by {} after {} quick-look messages\n", stop.signal_name(),
             board.state().messages());
}

void watch(PreviewArgs args) {
  if (args.http_given) return serve_dashboard(args);
  if (!args.session.empty())
    throw bad_input("--session shows a recorded run on the dashboard and needs --http (tomorig inspect prints the "
                    "history as text)");
  if (!(args.timeout_s >= 0)) throw bad_input(fmt::format("--timeout {:g} is invalid: it must be >= 0 seconds", args.timeout_s));
  if (!(args.view.png_interval_s >= 0))
    throw bad_input(fmt::format("--png-interval {:g} is invalid: it must be >= 0 seconds", args.view.png_interval_s));
  args.view.png_folder = args.png;
  args.view.source = args.from;
  args.view.tty = !args.view.json && isatty(STDOUT_FILENO) == 1;
  pipeline::QuickLookView view(args.view);

  zmq::context_t context(1);
  stream::SocketOptions socket = stream::preview_socket_options(args.from);
  socket.endpoint.bind = false;
  socket.timeout = 250ms;  // wakes up to notice Ctrl-C and --timeout
  stream::PreviewSubscriber subscriber(context, socket);
  fmt::print(stderr, "preview: listening on {}{}\n", args.from,
             args.count > 0 ? fmt::format(" for {} sets", args.count) : std::string(" (Ctrl-C ends)"));

  const rig::StopSignalGuard stop;
  auto last_message = Clock::now();
  while (!stop.stop_requested() && (args.count == 0 || view.sets() < args.count)) {
    std::optional<stream::PreviewMessage> message;
    try {
      message = subscriber.receive_message();
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;
      throw runtime_error(fmt::format("the preview stream from {} failed: {}", args.from, e.what()));
    }
    if (!message) {
      if (args.timeout_s > 0 && std::chrono::duration<double>(Clock::now() - last_message).count() > args.timeout_s)
        throw runtime_error(fmt::format("no quick-look results arrived from {} in {:g} s: is 'tomorig run --preview' "
                                        "or 'tomorig replay --preview' publishing there?",
                                        args.from, args.timeout_s));
      continue;
    }
    last_message = Clock::now();
    const std::string text = view.take(*message);
    fmt::print("{}", text);
    std::fflush(stdout);
  }
  fmt::print(stderr, "preview: {} sets shown{}\n", view.sets(),
             view.snapshots().empty() ? std::string()
                                      : fmt::format(", {} snapshots in {}", view.snapshots().size(), args.png));
}

}  // namespace

void add_preview_command(CLI::App& root) {
  auto args = std::make_shared<PreviewArgs>();
  CLI::App* cmd = root.add_subcommand(
      "preview", "Watch the quick-look of a running rig or replay: seeding, illumination, dt, alignment, light sheet");
  cmd->add_option("--from", args->from, "Preview endpoint to connect to (tomorig run --preview publishes there)")
      ->capture_default_str();
  cmd->add_flag("--json", args->view.json, "Print one JSON line per set (for scripts) instead of the view");
  cmd->add_option("--png", args->png, "Write snapshots with their numbers to this folder (created if needed)");
  cmd->add_option("--png-interval", args->view.png_interval_s, "Seconds between snapshots; 0: one per set")
      ->capture_default_str();
  cmd->add_flag("--overwrite", args->view.overwrite, "Replace snapshots already in the --png folder");
  cmd->add_option("--count", args->count, "Stop after this many sets (default: until Ctrl-C)");
  cmd->add_option("--timeout", args->timeout_s,
                  "Give up (exit 1) after this many seconds without a message (default: wait for ever)");
  add_http_options(*cmd, args->http);
  cmd->add_option("--status", args->status,
                  "With --http: also show the run's status stream (tomorig run --status), e.g. tcp://127.0.0.1:5556");
  cmd->add_option("--config", args->config_path,
                  "With --http: the rig file, for the trigger plan and the quick-look targets on the dashboard");
  cli::add_session_argument(*cmd, args->session,
                            "With --http: show this session's stored quick-look history instead of a live stream");
  cmd->callback([args, cmd] {
    args->http_given = args->http.given(*cmd);
    watch(*args);
  });
}

}  // namespace tomorig::app
