// tomorig replay: publishes a recorded session's FrameSets on the lossless stream (PUSH), as
// an acquisition process would, so that a recorder or a processing back end can be run and
// tested without a rig. Replay binds by default and the receiver (tomorig record) connects.
// Like `tomorig acquire` it frames the sets with a session start (the file's rig config,
// cameras, software version, creation time and truth), each set's truth just before the set,
// and an end of acquisition, so replay -> record copies a session faithfully.
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "http_options.h"
#include "json_summary.h"
#include "tomorig/core/console.h"
#include "tomorig/rig/replay_schedule.h"
#include "tomorig/rig/send_with_retry.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/core/error.h"
#include "tomorig/dashboard/live_dashboard.h"
#include "tomorig/dashboard/session_view.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/pipeline/stage_chain.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/preview.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::app {

using rig::ReplayRate;
using rig::ReplaySchedule;
using rig::SendOutcome;
using rig::SetRange;
using rig::StopSignalGuard;
using rig::make_replay_schedule;
using rig::parse_replay_rate;
using rig::parse_set_range;
using rig::send_with_retry;

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::duration_cast;

struct ReplayOptions {
  std::string file;
  JsonOutput json;
  std::string to = "tcp://127.0.0.1:5555";
  bool connect = false;
  bool allow_remote = false;
  std::string token;
  std::string rate = "recorded";
  bool loop = false;
  std::string sets;
  double timeout_s = 10.0;
  double wait_s = 60.0;
  std::vector<std::string> preview;  // --preview [ENDPOINT]
  bool preview_given = false;
  HttpChoices http;  // --http: the dashboard of the replay, fed by its quick-look
  bool http_given = false;
};

double seconds_since(Clock::time_point t) { return duration<double>(Clock::now() - t).count(); }

// One status line on stderr (StatusLine: redrawn on a terminal, a line every few seconds in a log).
class ReplayStatus {
 public:
  ReplayStatus() : last_(Clock::now()) {}

  void update(const stream::SenderStats& s, std::uint64_t blocked_sets, bool final = false) {
    if (!final && !line_.due()) return;
    const auto now = Clock::now();
    const double dt = duration<double>(now - last_).count();
    const double rate = dt > 0 ? static_cast<double>(s.sets_sent - last_sets_) / dt : 0.0;
    const double mbps = dt > 0 ? static_cast<double>(s.bytes_sent - last_bytes_) / dt / 1e6 : 0.0;
    const std::string text = fmt::format("replay: {} sets sent  {:.1f} sets/s  {:.1f} MB/s  {} blocked sends",
                                         s.sets_sent, rate, mbps, blocked_sets);
    if (final) line_.finish(text);
    else line_.update(text);
    last_ = now;
    last_sets_ = s.sets_sent;
    last_bytes_ = s.bytes_sent;
  }
  void break_line() { line_.break_line(); }

 private:
  StatusLine line_;
  Clock::time_point last_;
  std::uint64_t last_sets_ = 0, last_bytes_ = 0;
};

void replay(const ReplayOptions& opt) {
  if (!(opt.timeout_s > 0.0) || !(opt.wait_s > 0.0))
    throw bad_input(fmt::format("--timeout {:g} / --wait {:g} are invalid: both must be > 0 seconds", opt.timeout_s,
                                opt.wait_s));
  const ReplayRate rate = parse_replay_rate(opt.rate);
  const storage::SessionReader session(opt.file);
  if (session.set_count() == 0)
    throw bad_input(fmt::format("session '{}' holds no sets: nothing to replay", opt.file));
  const SetRange range = opt.sets.empty() ? SetRange{0, session.set_count()}
                                          : parse_set_range(opt.sets, session.set_count());
  std::vector<std::int64_t> trigger_ns;
  for (std::uint64_t i = range.first; i < range.last; ++i)
    trigger_ns.push_back(session.set_record(i).trigger_timestamp_ns);
  const ReplaySchedule schedule = make_replay_schedule(rate, trigger_ns);

  // --preview: the quick-look stage on every set sent, publishing for `tomorig preview`. It
  // skips sets to stay current, so it never holds the replay back.
  // --http turns it on at the default endpoint if --preview did not, and serves the dashboard
  // on it, subscribed like a separate `tomorig preview --http` would be.
  std::optional<pipeline::StageChain> quicklook;
  std::optional<dashboard::LiveDashboard> board;
  if (opt.preview_given || opt.http_given) {
    const std::string endpoint = pipeline::preview_endpoint(opt.preview);
    const std::optional<config::RigConfig> rig = dashboard::session_rig(session);
    const std::optional<dashboard::DashboardServerOptions> http =
        opt.http_given ? std::optional(http_server_options(opt.http, rig ? &rig->dashboard : nullptr)) : std::nullopt;
    quicklook = pipeline::make_chain(rig::all_stages(), {pipeline::quicklook_stage_spec(endpoint, {})});
    quicklook->begin(pipeline::describe_session(session));
    fmt::print(stderr, "replay: quick-look results on {} (watch: tomorig preview --from {})\n", endpoint, endpoint);
    if (http) {
      board.emplace(dashboard::InfoSource{.mode = "live", .source = opt.file, .rig = rig ? &*rig : nullptr},
                    dashboard::LiveFeedOptions{
                        .preview_endpoint = endpoint,
                        .notice = [](const std::string& text) { fmt::print(stderr, "replay: {}\n", text); }},
                    *http);
      fmt::print(stderr, "replay: dashboard on {}\n", board->url());
    }
  }

  StopSignalGuard stop;
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {opt.to, !opt.connect, opt.allow_remote};
  socket.endpoint.token = opt.token;
  socket.timeout = duration_cast<std::chrono::milliseconds>(duration<double>(opt.timeout_s));
  auto sender = std::make_unique<stream::FrameSender>(context, socket);
  // The first line names the real endpoint (a "*" port resolved), for scripts and tests.
  fmt::print(stderr, "replay: {} {}, sets {} to {} of {}, rate {}{}\n", opt.connect ? "connected to" : "sending on",
             sender->endpoint(), range.first, range.last - 1, opt.file, opt.rate, opt.loop ? ", looping" : "");
  std::fflush(stderr);

  stream::SessionStart start;
  start.session_id = stream::new_session_id();
  start.info = session.info();
  if (session.has_truth()) start.truth = session.truth();

  ReplayStatus status;
  std::uint64_t blocked_sets = 0;
  // The first message waits (up to --wait) for a receiver.
  const bool announced = send_with_retry(*sender, start, opt.wait_s, &stop) == SendOutcome::sent;
  bool stopped = !announced;
  auto pass_start = Clock::now();
  do {
    for (std::uint64_t i = range.first; i < range.last && !stopped; ++i) {
      const auto due = pass_start + schedule.due[i - range.first];
      if (stop.wait_for(due - Clock::now())) { stopped = true; break; }
      FrameSet set = session.read_set(i);
      set.set_index = i;
      const std::uint64_t blocked_before = sender->stats().blocked_sends;
      if (session.has_truth_set(i))
        send_with_retry(*sender, stream::SetTruth{start.session_id, set.trigger_index, session.truth_set(i)},
                        opt.timeout_s, nullptr);
      stopped = send_with_retry(*sender, set, opt.timeout_s, &stop) == SendOutcome::stopped;
      if (sender->stats().blocked_sends != blocked_before) ++blocked_sets;
      if (quicklook && !stopped) quicklook->push(set);
      status.update(sender->stats(), blocked_sets);
    }
    pass_start = rate.mode == ReplayRate::Mode::max ? Clock::now() : pass_start + schedule.pass_length;
  } while (opt.loop && !stopped && !stop.stop_requested());
  stopped = stopped || stop.stop_requested();
  if (announced) {
    // The end of the session: the recorder closes its file once it has the sets sent before.
    stream::SessionEnd end;
    end.session_id = start.session_id;
    end.sets_sent = sender->stats().sets_sent;
    if (stopped) {
      end.outcome = stream::SessionOutcome::stopped;
      end.reason = fmt::format("replay stopped by {}", stop.signal_name());
    }
    try {
      send_with_retry(*sender, end, opt.timeout_s, nullptr);
    } catch (const Error& e) {
      if (!stopped) throw;
      // Stopped by the operator, typically after the recorder: nobody is left to tell.
      status.break_line();
      fmt::print(stderr, "replay: {}\n", e.what());
    }
  }

  // Hand every queued set to the transport: closing the context waits (up to the linger, one
  // --timeout) until ZeroMQ has written all queued messages to the receiver. Waiting the whole
  // linger means it gave up with sets still queued.
  const stream::SenderStats sent = sender->stats();
  const std::string endpoint = sender->endpoint();
  sender.reset();
  const auto closing = Clock::now();
  context.close();
  const bool drained = seconds_since(closing) + 0.05 < opt.timeout_s;
  status.update(sent, blocked_sets, /*final=*/true);
  if (quicklook)
    for (const pipeline::StageReport& r : quicklook->end())
      fmt::print(stderr, "replay: stage {}\nreplay: {}\n", r.brief(), pipeline::quicklook_report_text(r));
  if (!drained)
    throw runtime_error(fmt::format("the receiver on {} stopped taking sets: sets still queued after {:g} s were "
                                    "lost ({} sets were handed to the transport)",
                                    endpoint, opt.timeout_s, sent.sets_sent));
  if (!opt.json.to_stdout())
    fmt::print("replayed {} sets ({:.1f} MB) from {} on {}{}\n", sent.sets_sent,
               static_cast<double>(sent.bytes_sent) / 1e6, opt.file, endpoint,
               stopped ? fmt::format(", stopped by {}", stop.signal_name()) : std::string());
  nlohmann::json j = json_summary("replay");
  j["session"] = opt.file;
  j["endpoint"] = endpoint;
  j[json_key::kSets] = sent.sets_sent;
  j["bytes"] = sent.bytes_sent;
  j["blocked_sends"] = blocked_sets;
  j["stopped_by"] = stopped ? std::string(stop.signal_name()) : std::string();
  emit_json(opt.json, j);
}

}  // namespace

void add_replay_command(CLI::App& root) {
  auto opt = std::make_shared<ReplayOptions>();
  CLI::App* cmd = root.add_subcommand(
      "replay", "Publish a session's frame sets on the lossless stream (binds; 'tomorig record' connects)");
  cmd->add_option("file", opt->file, "Session file (.h5) to replay")->required();
  cmd->add_option("--to", opt->to,
                  "Stream endpoint; replay binds it (loopback only unless --allow-remote). A port * binds any "
                  "free port, printed on stderr")
      ->capture_default_str();
  cmd->add_flag("--connect", opt->connect, "Connect to a receiver that binds (e.g. 'tomorig record --bind')");
  cmd->add_flag("--allow-remote", opt->allow_remote, "Allow binding to a non-loopback address (needs --token)");
  cmd->add_option("--token", opt->token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("--rate", opt->rate, "recorded (trigger timestamps) | max | a rate in Hz")->capture_default_str();
  cmd->add_flag("--loop", opt->loop, "Start over after the last set, until Ctrl-C");
  cmd->add_option("--sets", opt->sets, "Sets to send: A:B (A to B-1), A:, :B or A");
  cmd->add_option("--timeout", opt->timeout_s, "Seconds a send may wait for the receiver before giving up")
      ->capture_default_str();
  cmd->add_option("--wait", opt->wait_s,
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
