#pragma once
// The session a recorder is recording, as the stream's session messages describe it
// (docs/wire-protocol.md, "Session messages"): the announced session start (rig config,
// cameras, truth), the truth of sets not yet written, and the end of acquisition. A stream
// without a session start (an older sender) is still recorded: the first set then defines
// the cameras and the file says the rig configuration is unknown.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::rig {

class StreamSession {
 public:
  enum class StartOutcome {
    adopted,    // this start describes the session being recorded (or the one to record)
    repeated,   // the same start again: nothing changes
    conflict,   // another session started while one is being recorded: the recording must end
  };
  // `recording`: the session file is open already (from this start's cameras or a first set).
  StartOutcome on_start(stream::SessionStart start, bool recording);
  // Keeps the truth for the set with its trigger index (ignored unless it belongs to the
  // announced session). Holds at most a few dozen: truth whose set never came is dropped.
  void on_truth(stream::SetTruth truth);
  // True if `end` ends the announced session (an end of another session is ignored).
  bool on_end(const stream::SessionEnd& end);

  const std::optional<stream::SessionStart>& announced() const { return announced_; }
  const std::optional<stream::SessionEnd>& ended() const { return ended_; }
  // The announced cameras if their sizes are all known (the file can be opened before the
  // first set), else nullopt.
  std::optional<std::vector<storage::SessionCamera>> cameras_known_in_advance() const;
  // The session's cameras from its first set: the announced ones with open sizes filled in,
  // or, without an announcement, what the set shows. nullopt with `why` if the set cannot
  // start the session.
  std::optional<std::vector<storage::SessionCamera>> cameras_from_first_set(const FrameSet& set,
                                                                            std::string& why) const;
  // What the session file holds besides the frames; `source` names the stream for the
  // placeholder config of a stream without a session start.
  storage::SessionInfo file_info(std::vector<storage::SessionCamera> cameras, const std::string& source) const;
  // The truth of the set with this trigger index, once.
  std::optional<storage::TruthSet> take_truth(std::uint64_t trigger_index);

 private:
  std::optional<stream::SessionStart> announced_;
  std::optional<stream::SessionEnd> ended_;
  std::map<std::uint64_t, storage::TruthSet> truth_;
};

}  // namespace tomorig::rig
