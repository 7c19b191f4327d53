#pragma once
// Which trigger a software-triggered camera's frame answers, found by time. A camera numbers
// its frames, not trigger events: one trigger it missed (a camera not yet ready after
// AcquisitionStart, a command lost) would shift every later frame into the wrong set if
// frames were simply counted. The matcher knows when each trigger was sent (host clock) and
// learns the offset from the host's clock to the camera's from the frames it matched (the
// median of the last 16, per frame A and B triggers, so one late frame moves nothing): a frame answers the trigger whose
// time plus that offset is nearest its timestamp. Triggers passed over are counted as lost; a
// frame near no trigger answers none. The camera's clock never has to agree with the host's,
// only run at the same rate.
//
//   TriggerMatcher m(2, 20'000'000);                  // hardware: two frames per trigger
//   m.expect({event, host_ns});                       // before sending each trigger
//   if (auto hit = m.match(frame.frame_id, frame.timestamp_ns)) frame.trigger_index = *hit->event;
#include <cstdint>
#include <deque>
#include <vector>
#include <mutex>
#include <optional>

#include "tomorig/core/frame_set.h"

namespace tomorig::acquisition {

class TriggerMatcher {
 public:
  struct Trigger {
    std::optional<std::uint64_t> event;  // nullopt: a warm-up trigger whose frame is discarded
    Exposure exposure = Exposure::A;     // the frame it starts (two_triggers: A or B)
    std::int64_t host_ns = 0;            // when it was sent, host steady clock
  };
  struct Match {
    std::optional<std::uint64_t> event;
    Exposure exposure = Exposure::A;
  };

  // frames_per_trigger: 1 (two_triggers) or 2 (hardware: frame B follows frame A by id).
  // tolerance_ns: how far a frame's timestamp may be from where the trigger spacing puts it;
  // below half the closest spacing of two triggers. Throws bad_input otherwise out of range.
  // burst_separation_ns (frames_per_trigger 2, 0: unknown): frame B's time after frame A's by
  // the plan. With it the roles come from time, not from the frame counter's parity alone: a
  // frame right after a frame A is its B only if it follows it by that separation (within the
  // tolerance). A burst whose frame A never reached the host at all (the very first frame of a
  // run, say) would otherwise flip the parity of every later frame; the first frame that
  // contradicts the parity flips it back (and that mistaken frame A's offset is forgotten).
  TriggerMatcher(int frames_per_trigger, std::int64_t tolerance_ns, std::int64_t burst_separation_ns = 0);

  void expect(const Trigger& trigger);  // in the order the triggers are sent; thread-safe
  // The trigger `frame_id` (unwrapped frame counter) with camera timestamp `timestamp_ns`
  // answers, or nullopt (no trigger near it: the frame belongs to no set). Thread-safe.
  // burst_position (frames_per_trigger 2): the frame's place in its burst when the caller
  // knows it from the frame counter (bursts of two: even ids A, odd B). A frame B whose frame
  // A never arrived (incomplete, dropped) is then found by time and stays frame B, and a frame
  // A right after a lone frame B is not mistaken for that B's partner. Without it, a frame
  // that is not the id after an open frame A is taken for a frame A.
  std::optional<Match> match(std::uint64_t frame_id, std::int64_t timestamp_ns,
                             std::optional<Exposure> burst_position = std::nullopt);

  // Forgets the learned clock offsets: the camera's answer latency is about to change (its
  // triggers move to another phase of its readout). The next frame answers the oldest pending
  // trigger, as at the start. Thread-safe.
  void relearn_offsets();

  std::uint64_t triggers_lost() const;   // passed over: their frames never came
  std::uint64_t frames_unmatched() const;

 private:
  int frames_per_trigger_;
  std::int64_t tolerance_ns_;
  mutable std::mutex mutex_;
  std::deque<Trigger> pending_;
  // Camera timestamp - trigger time of recent matches, for triggers of frame A and of frame B
  // apart: a camera may answer one systematically later (Aravis's fake, whose 40 ms trigger
  // grid falls 20 ms later for a trigger sent 60 ms after the first).
  std::deque<std::int64_t> offsets_[2];
  int misses_in_a_row_ = 0;
  std::int64_t burst_separation_ns_ = 0;
  std::optional<Trigger> open_pair_;   // frames_per_trigger 2: the trigger whose frame B is next
  std::uint64_t open_pair_frame_id_ = 0;
  std::int64_t open_pair_timestamp_ns_ = 0;
  bool open_pair_taught_ = false;      // its frame A added an offset (offsets_[0].back())
  bool parity_flipped_ = false;        // the frame counter's parity says the opposite role
  std::uint64_t lost_ = 0;
  std::uint64_t unmatched_ = 0;
};

}  // namespace tomorig::acquisition
