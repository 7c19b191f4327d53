// tomorig acquire: the acquisition half of a split rig. Trigger device, cameras and FrameSet
// assembly as in `tomorig run`, but the sets leave over the lossless ZeroMQ stream (PUSH) for a
// `tomorig record` in another process, possibly on another host. It binds by default (the
// recorder connects); a full recorder slows acquisition down (back-pressure), it never drops.
//
// The stream carries the session as well as the sets: a session start (rig file, cameras with
// pixel pitch, the simulator's truth) goes out first, and the rig only starts once a recorder
// has taken it; each simulated set's truth goes just before the set; an end-of-acquisition
// message closes the session, so the recorder writes what `tomorig run` writes and stops by
// itself.
#include <cerrno>
#include <algorithm>
#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <zmq.hpp>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/rig/record_layout.h"
#include "tomorig/rig/rig_acquisition.h"
#include "tomorig/rig/rig_run_options.h"
#include "tomorig/rig/rig_session_info.h"
#include "tomorig/rig/send_with_retry.h"
#include "tomorig/rig/rig_status.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/frame_sender.h"

namespace tomorig::app {

using rig::rig_session_info;
using rig::LossTally;
using rig::RigAcquisition;
using rig::RigAcquisitionOptions;
using rig::RigProgress;
using rig::RigRunChoices;
using rig::SendOutcome;
using rig::StatusFigures;
using rig::StatusReporter;
using rig::StopSignalGuard;
using rig::add_rig_run_options;
using rig::load_rig;
using rig::rig_acquisition_options;
using rig::run_length_text;
using rig::send_with_retry;
using rig::pixel_bytes;

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::duration;
using std::chrono::duration_cast;

// The longest a send blocks before acquire looks at Ctrl-C again.
constexpr std::chrono::milliseconds kSendSlice{50};

struct AcquireOptions {
  RigRunChoices rig;
  JsonOutput json;
  std::string to = "tcp://127.0.0.1:5555";
  bool connect = false;
  bool allow_remote = false;
  std::string token;
  double timeout_s = 10.0;
  double wait_s = 60.0;
};

void acquire(const AcquireOptions& opt) {
  if (!(opt.timeout_s > 0.0) || !(opt.wait_s > 0.0))
    throw bad_input(fmt::format("--timeout {:g} / --wait {:g} are invalid: both must be > 0 seconds", opt.timeout_s,
                                opt.wait_s));
  const config::RigConfig rig = load_rig(opt.rig);
  RigAcquisitionOptions acquisition = rig_acquisition_options(rig, opt.rig);
  acquisition.keep_truth = true;  // simulated rigs: the recorder gets the truth `run` would write
  RigAcquisition rig_run(rig, acquisition);  // a bad rig fails here, before anything is sent

  StopSignalGuard stop;
  zmq::context_t context(1);
  stream::SocketOptions socket;
  socket.endpoint = {opt.to, !opt.connect, opt.allow_remote};
  socket.endpoint.token = opt.token;
  // Each send waits at most one slice, so Ctrl-C is seen within it even when the signal lands
  // on another thread than the one blocked in ZeroMQ; send_with_retry keeps trying for
  // --timeout (or --wait). Closing still waits one --timeout for queued sets.
  socket.linger = duration_cast<std::chrono::milliseconds>(duration<double>(opt.timeout_s));
  socket.timeout = std::min(kSendSlice, *socket.linger);
  auto sender = std::make_unique<stream::FrameSender>(context, socket);
  // The first line names the real endpoint (a "*" port resolved), for scripts and tests.
  fmt::print(stderr, "acquire: {} {}, rig '{}', {} cameras, {}\n", opt.connect ? "connected to" : "sending on",
             sender->endpoint(), rig.name, rig.cameras.size(),
             run_length_text(acquisition));
  std::fflush(stderr);
  StatusReporter status("acquire", context, opt.rig.status);
  if (!status.endpoint().empty()) fmt::print(stderr, "acquire: status JSON on {}\n", status.endpoint());

  LossTally losses(rig_run.camera_ids());
  StatusFigures figures;
  figures.total = acquisition.sets;
  figures.to_disk = false;
  auto refresh = [&](bool final) {
    const RigProgress progress = rig_run.progress();
    figures.queue_depth = progress.queued_sets;
    take_progress(figures, progress);
    status.update(figures, losses, final);
  };
  std::string stopped_by;
  stream::SessionStart session;
  session.session_id = stream::new_session_id();
  session.info = rig_session_info(rig, rig_run);
  session.truth = rig_run.session_truth();
  // Waits (up to --wait) for a recorder before the trigger fires, so no set queues up
  // unrecorded meanwhile; Ctrl-C while waiting ends the command with nothing acquired. A
  // connecting socket (--connect) would queue the session start with nobody there, so the
  // wait is for a connected recorder, then for it to take the session start.
  const auto wait_began = Clock::now();
  bool stopped_waiting = false;
  while (!sender->wait_for_receiver(kSendSlice)) {
    if (stop.stop_requested()) {
      stopped_waiting = true;
      break;
    }
    if (duration<double>(Clock::now() - wait_began).count() >= opt.wait_s)
      throw runtime_error(fmt::format("no recorder connected to {} within {:g} s (--wait): is 'tomorig record --{} {}' "
                                      "running?",
                                      sender->endpoint(), opt.wait_s, opt.connect ? "bind --from" : "from",
                                      sender->endpoint()));
  }
  if (stopped_waiting || send_with_retry(*sender, session, opt.wait_s, &stop) == SendOutcome::stopped) {
    fmt::print("no recorder took the session start; stopped by {} before acquiring\n", stop.signal_name());
    return;
  }
  rig_run.start();
  while (!rig_run.done()) {
    for (const auto& text : rig_run.take_notices()) {
      status.break_line();
      fmt::print(stderr, "acquire: {}\n", text);
    }
    if (stopped_by.empty() && stop.stop_requested()) {
      stopped_by = stop.signal_name();
      figures.state = "stopping";
      rig_run.request_stop();
    }
    std::optional<FrameSet> set = rig_run.pop(std::chrono::milliseconds(100));
    if (!set) {
      refresh(false);
      continue;
    }
    if (auto truth = rig_run.take_truth(set->trigger_index))
      send_with_retry(*sender, stream::SetTruth{session.session_id, set->trigger_index, std::move(*truth)},
                      opt.timeout_s, nullptr);
    // Ctrl-C interrupts a wait for the recorder; the set in hand and those already acquired
    // still go out, each with the normal timeout.
    if (send_with_retry(*sender, *set, opt.timeout_s, stopped_by.empty() ? &stop : nullptr) ==
        SendOutcome::stopped) {
      stopped_by = stop.signal_name();
      figures.state = "stopping";
      rig_run.request_stop();
      send_with_retry(*sender, *set, opt.timeout_s, nullptr);
    }
    losses.add(*set);
    ++figures.sets;
    figures.bytes += pixel_bytes(*set);
    refresh(false);
  }
  for (const auto& text : rig_run.take_notices()) fmt::print(stderr, "acquire: {}\n", text);
  rig_run.request_stop();

  // The end of acquisition: the recorder closes its file when it has every set sent before.
  stream::SessionEnd end;
  end.session_id = session.session_id;
  end.sets_sent = sender->stats().sets_sent;
  if (!rig_run.failure().empty()) {
    end.outcome = stream::SessionOutcome::failed;
    end.reason = rig_run.failure();
  } else if (!stopped_by.empty()) {
    end.outcome = stream::SessionOutcome::stopped;
    end.reason = "stopped by " + stopped_by;
  }
  try {
    send_with_retry(*sender, end, opt.timeout_s, nullptr);
  } catch (const Error& e) {
    if (stopped_by.empty()) throw;
    // Stopped by the operator, typically after the recorder: nobody is left to tell.
    fmt::print(stderr, "acquire: {}\n", e.what());
  }

  // Hand every queued set to the transport: closing the context waits (up to one --timeout of
  // linger) until ZeroMQ has written them to the recorder.
  const stream::SenderStats sent = sender->stats();
  const std::string endpoint = sender->endpoint();
  sender.reset();
  figures.state = rig_run.failure().empty() ? "stopped" : "failed";
  refresh(true);
  if (!opt.json.to_stdout())
    fmt::print("acquired and sent {} sets ({:.1f} MB) on {}; {} lost frames, {} incomplete sets{}\n", sent.sets_sent,
               static_cast<double>(sent.bytes_sent) / 1e6, endpoint, losses.frames_lost(), losses.incomplete_sets(),
               stopped_by.empty() ? "" : fmt::format(", stopped by {}", stopped_by));
  nlohmann::json j = json_summary("acquire");
  j["endpoint"] = endpoint;
  j[json_key::kSets] = sent.sets_sent;
  j["bytes"] = sent.bytes_sent;
  j["frames_lost"] = losses.frames_lost();
  j["incomplete_sets"] = losses.incomplete_sets();
  j["stopped_by"] = stopped_by;
  j["failure"] = rig_run.failure();
  emit_json(opt.json, j);
  if (!rig_run.failure().empty()) throw runtime_error(rig_run.failure());
}

}  // namespace

void add_acquire_command(CLI::App& root) {
  auto opt = std::make_shared<AcquireOptions>();
  CLI::App* cmd = root.add_subcommand(
      "acquire", "Run trigger and cameras and stream the frame sets to 'tomorig record' (binds; the recorder connects)");
  add_rig_run_options(*cmd, opt->rig, "Acquire");
  cmd->add_option("--to", opt->to, "Stream endpoint (tcp://127.0.0.1:* picks a free port)")->capture_default_str();
  cmd->add_flag("--connect", opt->connect, "Connect --to instead of binding (the recorder binds)");
  cmd->add_flag("--allow-remote", opt->allow_remote, "Allow binding --to on a non-loopback address (needs --token)");
  cmd->add_option("--token", opt->token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("--timeout", opt->timeout_s, "Seconds a send may wait for the recorder before giving up")
      ->capture_default_str();
  cmd->add_option("--wait", opt->wait_s, "Seconds to wait for a recorder to take the session start (the trigger "
                                        "starts after it)")
      ->capture_default_str();
  add_json_flag(*cmd, opt->json);
  cmd->callback([opt] { acquire(*opt); });
}

}  // namespace tomorig::app
