// tomorig acquire: the acquisition half of a split rig (rig::StreamAcquisition). Trigger device,
// cameras and FrameSet assembly as in `tomorig run`, but the sets leave over the lossless ZeroMQ
// stream (PUSH) for a `tomorig record` in another process, possibly on another host. It binds by
// default (the recorder connects); a full recorder slows acquisition down (back-pressure), it
// never drops.
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/rig_run_options.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_acquisition.h"

namespace tomorig::app {
namespace {

struct AcquireArgs {
  rig::RigRunChoices rig;                  // -c, --sets, --duration, --pace, ... (shared with run)
  rig::StreamAcquisitionOptions options;   // the stream's flags bind here
  JsonOutput json;
};

void acquire(AcquireArgs& args) {
  args.options.validate();  // the stream's flags first, as before the rig is loaded
  const config::RigConfig rig = rig::load_rig(args.rig);
  args.options.acquisition = rig::rig_acquisition_options(rig, args.rig);
  args.options.status_endpoint = args.rig.status;
  rig::StreamAcquisition acquisition(rig, args.options);  // a bad rig fails here, before anything is sent

  const rig::StopSignalGuard stop;
  rig::StreamAcquisitionHooks hooks;
  hooks.sending = [&](const std::string& endpoint) {
    // The first line names the real endpoint (a "*" port resolved), for scripts and tests.
    fmt::print(stderr, "acquire: {} {}, rig '{}', {} cameras, {}\n", args.options.connect ? "connected to" : "sending on",
               endpoint, rig.name, rig.cameras.size(), rig::run_length_text(args.options.acquisition));
    std::fflush(stderr);
  };
  hooks.status_socket = [](const std::string& endpoint) {
    fmt::print(stderr, "acquire: status JSON on {}\n", endpoint);
  };
  hooks.notice = [](const std::string& text) { fmt::print(stderr, "acquire: {}\n", text); };
  hooks.stop = &stop;
  const rig::StreamAcquisitionReport report = acquisition.run(hooks);

  if (!args.json.to_stdout()) fmt::print("{}\n", report.brief());
  nlohmann::json j = json_summary("acquire");
  j["endpoint"] = report.endpoint;
  j[json_key::kSets] = report.sets_sent;
  j["bytes"] = report.bytes_sent;
  j["frames_lost"] = report.frames_lost;
  j["incomplete_sets"] = report.incomplete_sets;
  j["stopped_by"] = report.stopped_by;
  j["failure"] = report.failure;
  emit_json(args.json, j);
  if (!report.failure.empty()) throw runtime_error(report.failure);
}

}  // namespace

void add_acquire_command(CLI::App& root) {
  auto args = std::make_shared<AcquireArgs>();
  rig::StreamAcquisitionOptions& o = args->options;
  CLI::App* cmd = root.add_subcommand(
      "acquire", "Run trigger and cameras and stream the frame sets to 'tomorig record' (binds; the recorder connects)");
  rig::add_rig_run_options(*cmd, args->rig, "Acquire");
  cmd->add_option("--to", o.to, "Stream endpoint (tcp://127.0.0.1:* picks a free port)")->capture_default_str();
  cmd->add_flag("--connect", o.connect, "Connect --to instead of binding (the recorder binds)");
  cmd->add_flag("--allow-remote", o.allow_remote, "Allow binding --to on a non-loopback address (needs --token)");
  cmd->add_option("--token", o.token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("--timeout", o.timeout_s, "Seconds a send may wait for the recorder before giving up")
      ->capture_default_str();
  cmd->add_option("--wait", o.wait_s, "Seconds to wait for a recorder to take the session start (the trigger "
                                      "starts after it)")
      ->capture_default_str();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { acquire(*args); });
}

}  // namespace tomorig::app
