#pragma once
// Assembles FrameSets from the frames of N cameras. Frames are keyed by trigger index; a set
// is emitted when all 2N frames have arrived, or when its timeout expires (then it is flagged
// incomplete, its missing frames left empty, and counted). Sets leave in trigger-index order.
// A frame arriving for a set already emitted is late: counted and dropped, never merged into
// another set. Thread-safe: cameras call add_frame() from their own threads, one consumer
// pops. Time comes from an injectable clock so tests drive timeouts without sleeping.
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

  // Throws bad_input naming the field.
  void validate() const;
};

struct CameraLoss {
  std::string camera_id;
  std::uint64_t frames_received = 0;  // frames placed into a set
  std::uint64_t frames_missing = 0;   // empty slots in emitted sets
  std::uint64_t frames_late = 0;      // arrived after their set was emitted (dropped)
  std::uint64_t frames_duplicate = 0; // a second frame for the same slot (dropped)
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

  // The next emitted set, if one is ready.
  std::optional<FrameSet> try_pop();
  // Waits up to `wait` (real time) for the next set, expiring timed-out sets meanwhile.
  std::optional<FrameSet> pop(std::chrono::milliseconds wait);
  std::size_t queued() const;

  AssemblyStatistics statistics() const;
  const AssemblerOptions& options() const { return options_; }

 private:
  struct Pending {
    FrameSet set;
    std::int64_t deadline_ns = 0;
    bool trigger_known = false;
    bool frame_timing_known = false;
  };

  void expire_locked(std::unique_lock<std::mutex>& lock, std::int64_t now);
  void emit_front_locked(std::unique_lock<std::mutex>& lock);
  Pending& pending_for_locked(std::uint64_t index, std::int64_t now);
  bool accept_index_locked(std::uint64_t index);

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
