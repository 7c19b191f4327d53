#pragma once
// A recorded session sent again on the lossless stream (PUSH), as an acquisition process would,
// so that a recorder or a processing back end can run without a rig (`tomorig replay`). The
// sets are framed like `acquire` frames them: a session start (the file's rig config, cameras,
// software version, creation time and truth), each set's truth just before the set, and a
// session end, so replay -> record copies a session faithfully.
//
// Options in, a report out: construction opens the session and checks everything (bad_input
// before any socket exists), run() sends.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "tomorig/core/frame_set.h"
#include "tomorig/rig/replay_schedule.h"

namespace tomorig::storage {
class SessionReader;
}

namespace tomorig::rig {

class StopSignalGuard;

struct SessionReplayOptions {
  std::filesystem::path session;              // the recorded session (.h5)
  std::string to = "tcp://127.0.0.1:5555";    // the stream endpoint; a port * binds any free port
  bool connect = false;                       // connect to a receiver that binds instead of binding
  bool allow_remote = false;                  // bind beyond loopback (needs a token)
  std::string token;                          // the stream's shared secret; empty: $TOMORIG_STREAM_TOKEN
  std::string rate = "recorded";              // "recorded" (trigger timestamps) | "max" | a rate in Hz
  bool loop = false;                          // start over after the last set until stopped
  std::string sets;                           // "A:B", "A:", ":B", "A"; empty: every set
  double timeout_s = 10.0;                    // how long one send may wait for the receiver
  double wait_s = 60.0;                       // how long the session start waits for a receiver
  bool status_line = false;                   // a status line on stderr ("replay: 12 sets sent ...")

  // bad_input naming the option and the fix.
  void validate() const;
};

struct SessionReplayHooks {
  // The endpoint as bound (port resolved) or connected, before the first message is sent.
  std::function<void(const std::string& endpoint)> sending;
  // Each set once it is sent (e.g. to a quick-look chain).
  std::function<void(const FrameSet& set)> sent;
  // Messages for the operator, printed on a fresh line.
  std::function<void(const std::string& text)> notice;
  // Ctrl-C: answered between sets and while a send waits; nullptr: no stop but the end.
  const StopSignalGuard* stop = nullptr;
};

struct SessionReplayReport {
  std::string session;
  std::string endpoint;  // as bound or connected
  SetRange range;
  std::uint64_t sets_sent = 0;
  std::uint64_t bytes_sent = 0;
  std::uint64_t blocked_sets = 0;  // sets whose send found the receiver's queue full
  bool announced = false;          // a receiver took the session start
  bool stopped = false;            // a stop signal ended the replay (or nobody took the start)
  std::string stopped_by;          // "SIGINT", "SIGTERM" or ""
  // Why sets were lost after all were handed to the transport (the receiver stopped taking
  // them); empty when every set was delivered to the receiver's queue.
  std::string failure;

  // "replayed 12 sets (3.1 MB) from s.h5 on tcp://127.0.0.1:5555[, stopped by SIGINT]"
  std::string brief() const;
};

class SessionReplay {
 public:
  // Opens the session and plans the sends; bad_input for bad options or a session without sets.
  explicit SessionReplay(SessionReplayOptions options);
  ~SessionReplay();
  SessionReplay(const SessionReplay&) = delete;
  SessionReplay& operator=(const SessionReplay&) = delete;

  const storage::SessionReader& session() const;
  SetRange range() const;

  // Sends the sets (looping if asked) and the session end, then waits (up to one timeout) until
  // ZeroMQ has handed every queued message to the receiver. Throws runtime_error when a send
  // times out (the receiver is gone or stuck). Call once.
  SessionReplayReport run(const SessionReplayHooks& hooks = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::rig
