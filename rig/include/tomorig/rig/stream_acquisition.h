#pragma once
// The acquisition half of a split rig (`tomorig acquire`): trigger device, cameras and FrameSet
// assembly as in `tomorig run` (RigAcquisition), but the sets leave over the lossless ZeroMQ
// stream (PUSH) for a StreamRecording in another process, possibly on another host. A full
// recorder slows acquisition down (back-pressure); nothing is dropped.
//
// The stream carries the session as well as the sets (docs/wire-protocol.md, "Session
// messages"): a session start (rig file, cameras with pixel pitch, the simulator's truth) goes
// out first and the trigger only starts once a recorder has taken it; each simulated set's
// truth goes just before the set; a session end closes the session, so the recorder writes what
// `tomorig run` writes and stops by itself.
//
// Options in, a report out: construction checks the options and builds and arms the rig (a bad
// rig fails before any socket exists), run() acquires and sends.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/rig/rig_acquisition.h"

namespace tomorig::rig {

class StopSignalGuard;

struct StreamAcquisitionOptions {
  RigAcquisitionOptions acquisition;          // sets, duration, pacing, camera loss, faults
  std::string to = "tcp://127.0.0.1:5555";    // the stream endpoint; a port * binds any free port
  bool connect = false;                       // connect to a recorder that binds instead of binding
  bool allow_remote = false;                  // bind beyond loopback (needs a token)
  std::string token;                          // the stream's shared secret; empty: $TOMORIG_STREAM_TOKEN
  double timeout_s = 10.0;                    // how long one send may wait for the recorder
  double wait_s = 60.0;                       // how long the session start waits for a recorder
  // Where the JSON status PUB socket binds; empty or "none": no socket. The status line on
  // stderr ("acquire: set 3/3 ...") is always drawn.
  std::string status_endpoint = "tcp://127.0.0.1:5556";
  std::string status_label = "acquire";       // starts the status line

  // bad_input naming the option and the fix.
  void validate() const;
};

struct StreamAcquisitionHooks {
  // The stream endpoint as bound (port resolved) or connected, before anything is sent.
  std::function<void(const std::string& endpoint)> sending;
  // The status socket's endpoint once bound (not called without a socket).
  std::function<void(const std::string& endpoint)> status_socket;
  // Messages for the operator (a camera vanished, ...), on a fresh line.
  std::function<void(const std::string& text)> notice;
  // Each set once it is handed to the stream.
  std::function<void(const FrameSet& set)> sent;
  // Ctrl-C: ends the wait for a recorder, or the acquisition (the sets already taken still go
  // out); nullptr: only the rig's end.
  const StopSignalGuard* stop = nullptr;
};

struct StreamAcquisitionReport {
  std::string endpoint;            // as bound or connected
  bool announced = false;          // a recorder took the session start (else nothing was acquired)
  std::uint64_t sets_sent = 0;
  std::uint64_t bytes_sent = 0;
  std::uint64_t frames_lost = 0;   // empty frames in the sets sent
  std::uint64_t incomplete_sets = 0;
  std::string stopped_by;          // "SIGINT", "SIGTERM" or ""
  // Why the rig ended on its own (a camera lost under the stop policy, a device error); the
  // sets before it were sent and the session end says so. Empty otherwise.
  std::string failure;

  // "acquired and sent 12 sets (3.1 MB) on tcp://127.0.0.1:5555; 0 lost frames, 0 incomplete
  // sets[, stopped by SIGINT]", or why nothing was acquired.
  std::string brief() const;
};

class StreamAcquisition {
 public:
  // bad_input for bad options; a bad rig (safety limit, feature, absent camera) throws as
  // RigAcquisition does. No socket exists yet.
  StreamAcquisition(const config::RigConfig& rig, StreamAcquisitionOptions options);
  ~StreamAcquisition();
  StreamAcquisition(const StreamAcquisition&) = delete;
  StreamAcquisition& operator=(const StreamAcquisition&) = delete;

  const RigAcquisition& acquisition() const;

  // Waits (up to wait_s) for a recorder to take the session start, runs the rig, sends every
  // set (with its truth) and the session end, then waits (up to one timeout) until ZeroMQ has
  // handed the queued sets to the recorder. Throws runtime_error when no recorder comes within
  // wait_s or a send times out. A rig failure is returned in the report. Call once.
  StreamAcquisitionReport run(const StreamAcquisitionHooks& hooks = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::rig
