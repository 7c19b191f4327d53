// tomorig record: the recorder half of a split rig (rig::StreamRecording). Pulls FrameSets from
// the lossless stream (tomorig replay, or an acquisition process) and writes them live (HDF5
// SWMR), so the file can be inspected while it grows and survives a crash. It connects by
// default; the sender binds.
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "commands.h"
#include "json_summary.h"
#include "tomorig/core/console.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_recording.h"

namespace tomorig::app {
namespace {

struct RecordArgs {
  rig::StreamRecordingOptions options;  // every flag binds here
  JsonOutput json;
};

void record(RecordArgs& args) {
  args.options.status_line = true;
  rig::StreamRecording recording(args.options);
  const rig::StopSignalGuard stop;
  rig::StreamRecordingHooks hooks;
  hooks.receiving = [&](const std::string& endpoint) {
    fmt::print(stderr, "record: {} {}, writing {}\n", args.options.bind ? "receiving on" : "receiving from", endpoint,
               args.options.recorder.out.string());
    std::fflush(stderr);
  };
  hooks.notice = [](const std::string& text) { fmt::print(stderr, "record: {}\n", text); };
  if (verbosity() == Verbosity::verbose)
    hooks.wrote = [](const FrameSet& set, std::uint64_t index) {
      spdlog::debug("record: wrote set {} (trigger {}) as set {}", set.set_index, set.trigger_index, index);
    };
  hooks.stopped_early = [](const std::string& brief) { fmt::print("{}\n", brief); };
  hooks.stop = &stop;
  const rig::StreamRecordingReport report = recording.run(hooks);

  const auto refused_peers = stream::refused_connections();
  if (!args.json.to_stdout()) {
    fmt::print("{}\n", report.brief());
    if (refused_peers.count > 0)
      fmt::print("{} connections refused for a wrong token (last from {})\n", refused_peers.count,
                 refused_peers.last_peer);
    fmt::print("next: tomorig inspect {}\n", report.recording.out.string());
  }
  nlohmann::json j = json_summary("record");
  j[json_key::kOut] = report.recording.out.string();
  j[json_key::kSets] = report.recording.written;
  j["bytes"] = report.recording.bytes;
  j["lost_sets"] = report.received.sets_missing;
  j["refused_sets"] = report.recording.refused;
  j["rejected_messages"] = report.rejected;
  j["refused_connections"] = refused_peers.count;
  j["sender_outcome"] = report.sender_end ? std::string(to_string(report.sender_end->outcome)) : std::string();
  j["stopped_by"] = report.stopped_by;
  emit_json(args.json, j);
  if (const std::string failure = report.failure(); !failure.empty()) throw runtime_error(failure);
}

}  // namespace

void add_record_command(CLI::App& root) {
  auto args = std::make_shared<RecordArgs>();
  CLI::App* cmd = root.add_subcommand(
      "record", "Record frame sets from the lossless stream into a session file (connects; the sender binds)");
  cmd->add_option("--from", args->options.from, "Stream endpoint of the sender (tomorig replay / acquire)")
      ->capture_default_str();
  cmd->add_flag("--bind", args->options.bind, "Bind --from instead of connecting (then the sender connects)");
  cmd->add_flag("--allow-remote", args->options.allow_remote, "Allow --bind on a non-loopback address (needs --token)");
  cmd->add_option("--token", args->options.token, "Shared secret of the stream (default: $TOMORIG_STREAM_TOKEN); required beyond loopback, both sides alike");
  cmd->add_option("-o,--out", args->options.recorder.out, "Session file to write (.h5)")->required();
  cmd->add_option("--sets", args->options.sets, "Stop after this many sets (default: at the sender's end of acquisition, Ctrl-C or --idle-timeout)");
  cmd->add_option("--compression", args->options.compression, "Frame compression: none | bitshuffle-lz4")
      ->capture_default_str();
  cmd->add_option("--idle-timeout", args->options.idle_timeout_s,
                  "Stop when no set arrived for this many seconds (counted from the start until the first set); 0: "
                  "wait for ever")
      ->capture_default_str();
  cmd->add_flag("--overwrite", args->options.recorder.overwrite, "Replace an existing output file");
  cmd->add_option("--disk-reserve-mb", args->options.recorder.disk_reserve_mb,
                  "Stop recording cleanly when the disk would have less than this many MB free")
      ->capture_default_str();
  cmd->add_option("--max-set-mb", args->options.recorder.max_set_mb,
                  "Refuse a first set larger than this many MB of pixels (it would size the session)")
      ->capture_default_str();
  add_json_flag(*cmd, args->json);
  cmd->callback([args] { record(*args); });
}

}  // namespace tomorig::app
