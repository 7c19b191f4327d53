#pragma once
// Assembles FrameSets from the frames of N cameras. Frames are keyed by trigger index; a set
// is emitted when all 2N frames have arrived, or when its timeout expires (then it is flagged
// incomplete, its missing frames left empty, and counted). Sets leave in trigger-index order.
// A frame arriving for a set already emitted is late: counted and dropped, never merged into
// another set. A camera's pair whose timestamps disagree with the timing plan (B - A outside
// the expected separation ± tolerance) came from different trigger events: both frames are
// dropped and counted, so a set never holds frames of two events. Thread-safe: cameras call
// add_frame() from their own threads, one consumer pops. Time comes from an injectable clock
// so tests drive timeouts without sleeping.
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/acquisition/camera.h"
#include "tomorig/acquisition/trigger_input.h"
#include "tomorig/core/frame_set.h"

namespace tomorig::acquisition {

// Monotonic time in ns; the default reads std::chrono::steady_clock.
using AssemblyClock = std::function<std::int64_t()>;

struct AssemblerOptions {
  std::vector<std::string> camera_ids;  // camera order in every FrameSet; at least one
  // A set not complete this long after its first frame (or trigger) arrived is emitted
  // incomplete. Set it above the worst frame latency: a frame arriving later is lost.
  std::chrono::nanoseconds timeout = std::chrono::milliseconds(500);
  // Trigger index of the first set; earlier indices are late. nullopt: the first index seen.
  std::optional<std::uint64_t> first_trigger_index = 0;
  // A trigger index further than this ahead of the oldest pending set is treated as bogus
  // (counted as rejected), so a corrupt index cannot create millions of empty sets.
  std::uint64_t max_index_jump = 4096;
  // Sets held for the consumer before add_frame() waits for it (back-pressure, no drops).
  std::size_t max_queued_sets = 64;
  // The run's end: trigger indices from here on are not part of it (frames counted as
  // `frames_beyond_run`, triggers ignored), so a camera's extra frames never make extra sets.
  std::optional<std::uint64_t> end_trigger_index;

  // Per camera (empty, or one entry per camera id), how its frames are checked and placed.
  struct CameraPairing {
    // Frame B's timestamp minus frame A's, on the camera's own clock, must lie within
    // expected_separation_ns ± tolerance_ns; tolerance_ns 0: not checked.
    std::int64_t expected_separation_ns = 0;
    std::int64_t tolerance_ns = 0;
    // A free-running camera: its frames carry no trigger index; each frame fills the next
    // empty slot (A, then B) of the oldest pending set announced by add_trigger() before the
    // frame arrived, and is marked unsynchronised. Frames no set waits for are surplus.
    bool free_running = false;
  };
  std::vector<CameraPairing> pairing;

  // Throws bad_input naming the field.
  void validate() const;
};

struct CameraLoss {
  std::string camera_id;
  std::uint64_t frames_received = 0;  // frames placed into a set
  std::uint64_t frames_missing = 0;   // empty slots in emitted sets
  std::uint64_t frames_late = 0;      // arrived after their set was emitted (dropped)
  std::uint64_t frames_duplicate = 0; // a second frame for the same slot (dropped)
  std::uint64_t frames_mismatched = 0;  // dropped because B - A disagreed with the plan
  std::uint64_t frames_beyond_run = 0;  // for trigger indices past the run's end (dropped)
  std::uint64_t frames_surplus = 0;     // free-running: frames no set waited for (dropped)
  bool lost = false;                    // mark_camera_lost(): sets no longer wait for it
  std::string last_mismatch;            // why the latest mismatched pair was dropped
};

struct AssemblyStatistics {
  std::uint64_t sets_emitted = 0;
  std::uint64_t sets_complete = 0;
  std::uint64_t sets_incomplete = 0;   // emitted with at least one frame missing
  std::uint64_t frames_rejected = 0;   // bad camera number or implausible trigger index
  std::vector<CameraLoss> cameras;     // in camera order
};

class FrameSetAssembler {
 public:
  explicit FrameSetAssembler(AssemblerOptions options, AssemblyClock clock = {});

  // Places a frame of camera `camera` (index into options.camera_ids). Thread-safe.
  void add_frame(std::size_t camera, CameraFrame frame);
  // Records the trigger time and actual Δt of an event; a set with a known trigger is
  // created (and its timeout started) even if no frame of it ever arrives. Thread-safe.
  void add_trigger(const TriggerInput& trigger);
  // Emits every pending set whose timeout has expired (by the clock). add_frame and the pop
  // functions call it too; a consumer with a fake clock calls it after advancing the clock.
  void expire();
  // Emits every pending set now, complete or not (end of acquisition).
  void flush();
  // The camera is gone: pending and later sets stop waiting for its frames (they are emitted
  // as soon as the other cameras' frames are in, flagged incomplete). Thread-safe.
  void mark_camera_lost(std::size_t camera);

  // The next emitted set, if one is ready.
  std::optional<FrameSet> try_pop();
  // Waits up to `wait` (real time) for the next set, expiring timed-out sets meanwhile.
  std::optional<FrameSet> pop(std::chrono::milliseconds wait);
  std::size_t queued() const;
  // Sets still being assembled (not yet emitted).
  std::size_t pending() const;

  AssemblyStatistics statistics() const;
  const AssemblerOptions& options() const { return options_; }

 private:
  struct Pending {
    FrameSet set;
    std::int64_t deadline_ns = 0;
    std::int64_t announced_ns = 0;  // clock time of add_trigger(); free-running frames wait for it
    bool trigger_known = false;
    bool frame_timing_known = false;
  };

  void expire_locked(std::unique_lock<std::mutex>& lock, std::int64_t now);
  void emit_front_locked(std::unique_lock<std::mutex>& lock);
  Pending& pending_for_locked(std::uint64_t index, std::int64_t now);
  bool accept_index_locked(std::uint64_t index);
  bool ready_locked(const Pending& p) const;  // every frame the set still waits for is in
  void place_locked(std::size_t camera, Pending& p, CameraFrame&& frame);
  void place_free_running_locked(std::size_t camera, CameraFrame&& frame);
  void check_pairs_locked(FrameSet& set);
  const AssemblerOptions::CameraPairing* pairing_of(std::size_t camera) const;

  AssemblerOptions options_;
  AssemblyClock clock_;
  mutable std::mutex mutex_;
  std::condition_variable ready_;    // a set was queued
  std::condition_variable drained_;  // the consumer took a set (back-pressure)
  std::map<std::uint64_t, Pending> pending_;
  std::optional<std::uint64_t> next_index_;  // lowest index not yet emitted
  std::deque<FrameSet> queue_;
  std::uint64_t next_set_index_ = 0;
  AssemblyStatistics stats_;
};

}  // namespace tomorig::acquisition
