#pragma once
// The recorder half of a split rig (`tomorig record`): pulls FrameSets from the lossless stream
// (`tomorig replay`, `tomorig acquire`) and writes them with rig::Recorder, live (HDF5 SWMR).
// The sender's session start gives the file the rig config, pixel pitch and truth a `tomorig
// run` file has, and its session end ends the recording (docs/wire-protocol.md, "Session
// messages"). Options in, a report out: construction checks the options and the output (before
// any socket exists), run() records.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "tomorig/core/frame_set.h"
#include "tomorig/rig/recorder.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::rig {

class StopSignalGuard;

struct StreamRecordingOptions {
  std::string from = "tcp://127.0.0.1:5555";  // the sender's endpoint
  bool bind = false;                          // bind `from` instead of connecting
  bool allow_remote = false;                  // bind beyond loopback (needs a token)
  std::string token;                          // the stream's shared secret; empty: $TOMORIG_STREAM_TOKEN
  std::optional<std::uint64_t> sets;          // stop after this many sets; none: at the sender's end
  // Stop when no set arrived for this long (counted from the start until the first set); 0: wait
  // for ever. A rig triggers at 1 Hz or faster, so a minute without a set means the acquisition
  // has stopped (issue 23: a record after a replay that had ended waited for ever); until the
  // first set the minute also covers the start of the sender.
  double idle_timeout_s = 60.0;
  std::string compression = "none";           // "none" | "bitshuffle-lz4"
  RecorderOptions recorder;                   // out, overwrite, disk reserve, largest set
  bool status_line = false;                   // "record: 12 sets  41.9 MB/s to disk ..." on stderr
};

struct StreamRecordingHooks {
  // The endpoint as bound or connected, before anything is received.
  std::function<void(const std::string& endpoint)> receiving;
  // Messages for the operator: a session adopted, a set or message refused (the first few).
  std::function<void(const std::string& text)> notice;
  // Each set written, with its index in the file (for a verbose log).
  std::function<void(const FrameSet& set, std::uint64_t written_index)> wrote;
  // A full disk closed the session early: its summary, before run() throws.
  std::function<void(const std::string& brief)> stopped_early;
  // Ctrl-C: ends the recording cleanly; nullptr: only the sender's end, --sets or the idle timeout.
  const StopSignalGuard* stop = nullptr;
};

struct StreamRecordingReport {
  RecorderReport recording;          // refusals before the session start included
  stream::ReceiverStats received;
  std::uint64_t received_sets = 0;   // frame sets of the recorded session that arrived (written or refused)
  std::uint64_t rejected = 0;        // messages the decoder refused
  std::optional<stream::SessionEnd> sender_end;
  std::string stopped_by;            // a signal or the idle timeout; empty otherwise
  std::string new_session;           // another session that started meanwhile (hex id); empty if none
  std::string endpoint;

  // "<recording>; 0 lost sets, 0 refused sets, 0 rejected messages, 2 session messages[; ending]"
  std::string brief() const;
  // Why the file, complete as it is, lacks sets the sender sent (sets lost on the way, or another
  // session cut this one short); empty if none.
  std::string failure() const;
};

class StreamRecording {
 public:
  // bad_input for bad options or an output that exists without overwrite.
  explicit StreamRecording(StreamRecordingOptions options);

  // Records until the sender's end, `sets`, the idle timeout or a stop. Throws runtime_error if
  // nothing could be recorded, if the disk filled up (the file is complete with the sets before)
  // or the stream failed.
  StreamRecordingReport run(const StreamRecordingHooks& hooks = {});

 private:
  StreamRecordingOptions options_;
};

}  // namespace tomorig::rig
