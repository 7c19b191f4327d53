#pragma once
// One trigger event of a double-frame rig: N cameras x (frame A, frame B), with timestamps.
// Live acquisition and replay both produce FrameSets, so every consumer handles both.
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/core/image.h"

namespace tomorig {

enum class Exposure : std::uint8_t { A = 0, B = 1 };

struct Frame {
  Image image;                    // empty if the frame was lost
  std::int64_t timestamp_ns = 0;  // camera or trigger clock, ns
  // false: a free-running camera's frame, taken near the event but not exposed by its
  // trigger (frame_mode "free_run"); such a frame never makes a set complete.
  bool synchronised = true;
  bool present() const { return !image.empty(); }
};

struct CameraFrames {
  std::string camera_id;
  Frame a;
  Frame b;
  Frame& operator[](Exposure e) { return e == Exposure::A ? a : b; }
  const Frame& operator[](Exposure e) const { return e == Exposure::A ? a : b; }
};

struct FrameSet {
  std::uint64_t set_index = 0;       // position in the session, 0-based
  std::uint64_t trigger_index = 0;   // trigger event counter from the trigger device
  std::int64_t trigger_timestamp_ns = 0;
  std::int64_t dt_ns = 0;            // pulse separation between exposures A and B
  std::vector<CameraFrames> cameras;

  // Number of frames (of 2 * cameras.size()) that are missing.
  int missing_frames() const {
    int missing = 0;
    for (const auto& c : cameras) missing += (c.a.present() ? 0 : 1) + (c.b.present() ? 0 : 1);
    return missing;
  }
  // Present frames that were not exposed by this trigger event (free-running cameras).
  int unsynchronised_frames() const {
    int n = 0;
    for (const auto& c : cameras)
      n += (c.a.present() && !c.a.synchronised ? 1 : 0) + (c.b.present() && !c.b.synchronised ? 1 : 0);
    return n;
  }
  // Every frame present and exposed by this event: a set fit for PIV.
  bool complete() const { return missing_frames() == 0 && unsynchronised_frames() == 0; }
};

}  // namespace tomorig
