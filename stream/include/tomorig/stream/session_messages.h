#pragma once
// Session messages on the lossless stream (byte layout: docs/wire-protocol.md, "Session
// messages"). A sender announces a session before its first frame set (what a session file
// holds besides the frames: rig config, cameras with pixel pitch, the simulator's truth), may
// send the truth of each set just before that set, and ends with an end-of-acquisition message
// saying how many sets it sent and why it stopped. A recorder then writes the same file as
// `tomorig run` and stops by itself. A stream without them (an older sender) is still a valid
// stream of frame sets. Encoding and decoding: tomorig/stream/wire_format.h.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::stream {

// Layout version of the session messages (bytes 8-9), independent of the frame-set version:
// raise it on any change of their layout or meaning; a receiver refuses another version.
inline constexpr std::uint16_t kSessionFormatVersion = 1;

struct SessionStart {
  // Random and non-zero per sending run: ties truth and end to this start, so an end left
  // over from another sender's session cannot close this one.
  std::uint64_t session_id = 0;
  // Cameras (width and height 0: not known until the first set, e.g. an Aravis camera
  // without an ROI), rig config text, software version and creation time of the session.
  // `compression` is not sent: the recorder chooses its own.
  storage::SessionInfo info;
  std::optional<storage::SessionTruth> truth;  // simulated rigs
};

// The simulator's particles of one set: applies to the next frame set with this trigger index.
struct SetTruth {
  std::uint64_t session_id = 0;
  std::uint64_t trigger_index = 0;
  storage::TruthSet particles;
};

enum class SessionOutcome : std::uint8_t {
  completed = 0,  // every set asked for was sent
  stopped = 1,    // the operator stopped it (Ctrl-C), sets sent so far are complete
  failed = 2,     // the sender ended early on an error named in `reason`
};
std::string_view to_string(SessionOutcome outcome);

struct SessionEnd {
  std::uint64_t session_id = 0;
  std::uint64_t sets_sent = 0;  // frame sets of this session the sender handed to the stream
  SessionOutcome outcome = SessionOutcome::completed;
  std::string reason;  // why it stopped or failed; empty when completed
};

using StreamMessage = std::variant<FrameSet, SessionStart, SetTruth, SessionEnd>;

// A fresh random session id (never 0).
std::uint64_t new_session_id();

}  // namespace tomorig::stream
