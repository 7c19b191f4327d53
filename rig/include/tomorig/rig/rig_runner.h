#pragma once
// The live rig in one process, as `tomorig run` drives it:
//
//   trigger -> cameras -> FrameSetAssembler -> (pump thread) inproc PUSH -> PULL -> Recorder
//
// The recorder takes sets from the same kind of stream a separate `tomorig record` would, so
// the in-process rig and the split rig (acquire + record) share one data path. Options in, a
// report out: construction checks and arms everything (a bad rig or output fails before any
// file exists), run() records until the rig is done, the disk is full or a stop is asked for.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/rig/recorder.h"
#include "tomorig/rig/rig_acquisition.h"

namespace tomorig::rig {

struct RigRunOptions {
  RigAcquisitionOptions acquisition;
  // Where and how to record; the cameras, the rig's TOML and (simulated rigs) the truth are
  // filled in by the runner.
  RecorderOptions recorder;
  // Where the JSON status PUB socket binds; empty or "none": no socket.
  std::string status_endpoint = "tcp://127.0.0.1:5556";
  std::string status_label = "recording";  // starts the status line on stderr
  // More stages fed with every recorded set (rig::all_stages() names them): a quick-look that
  // may skip sets to stay current, a live back-end, ... Configured before the rig is built.
  std::vector<pipeline::StageSpec> stages;
  // Messages for the operator (a camera vanished, ...), printed on a fresh line.
  std::function<void(const std::string&)> notice;
};

struct RigRunReport {
  RecorderReport recording;
  std::size_t cameras = 0;
  std::uint64_t frames_lost = 0;
  std::uint64_t incomplete_sets = 0;
  std::string failure;   // why the rig ended on its own (a camera lost, a device error); empty otherwise
  bool stopped = false;  // should_stop ended the run
  double seconds = 0.0;  // from start to the session closed
  std::uintmax_t file_bytes = 0;
  std::vector<pipeline::StageReport> stages;  // of RigRunOptions::stages, in order

  // "wrote s.h5: 12 sets x 4 cameras, 3.1 MiB in 1.52 s; 0 lost frames, 0 incomplete sets"
  std::string brief() const;
};

using StopCondition = std::function<bool(const RecorderReport& so_far)>;

class RigRunner {
 public:
  // Checks the output, builds, configures and arms the rig and creates the session when the
  // camera sizes are known. Throws tomorig::Error (bad_input) for a bad rig or output.
  RigRunner(const config::RigConfig& rig, RigRunOptions options);
  ~RigRunner();
  RigRunner(const RigRunner&) = delete;
  RigRunner& operator=(const RigRunner&) = delete;

  // The endpoint the status socket is bound to, or "" if none.
  std::string status_endpoint() const;
  // Runs the rig and records until it is done. `should_stop` is asked between sets with the
  // recording so far; true ends
  // the run: acquisition stops, the sets already taken are recorded and the session is closed
  // complete (report.stopped). Throws runtime_error if no set could be recorded; a full disk or
  // a rig failure still returns the report of the complete session (recording.disk_full,
  // failure): the caller says what went wrong. Call once.
  RigRunReport run(const StopCondition& should_stop = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// "3.1 MiB", "12.0 KiB", "512 B".
std::string human_bytes(std::uintmax_t bytes);

}  // namespace tomorig::rig
