#pragma once
// Camera frame counters are short: GigE Vision 1.x block ids are 16 bits and skip 0
// (65535 is followed by 1). FrameIdUnwrapper turns such a counter into a monotonic 64-bit
// sequence so that a frame's position (and so its set and A/B role) survives the wrap.
#include <cstdint>
#include <optional>

namespace tomorig::acquisition {

class FrameIdUnwrapper {
 public:
  // bits: width of the raw counter (1..63); zero_reserved: the counter never takes the value 0.
  explicit FrameIdUnwrapper(int bits = 16, bool zero_reserved = true);

  // The unwrapped sequence number of `raw`: the first id maps to 0, the next id to 1, and so
  // on across wraps. An id more than half a cycle behind the newest is reported as
  // std::nullopt (a stale or duplicate frame), and does not move the sequence.
  std::optional<std::uint64_t> unwrap(std::uint64_t raw);

  // Declares the raw id the first frame will carry (a camera that restarts its counter at
  // AcquisitionStart). Without it the first id received becomes frame 0, so a first frame
  // lost entirely would shift every later frame's A/B role by one.
  void expect_first(std::uint64_t raw);

  // Frames skipped by the ids seen so far (a jump of 3 means 2 frames never arrived).
  std::uint64_t gaps() const { return gaps_; }

 private:
  std::uint64_t position(std::uint64_t raw) const;  // raw id -> place in the cycle [0, cycle_)

  std::uint64_t cycle_;
  bool zero_reserved_;
  std::uint64_t mask_;
  bool started_ = false;
  std::uint64_t last_position_ = 0;
  std::uint64_t last_sequence_ = 0;
  std::uint64_t gaps_ = 0;
};

}  // namespace tomorig::acquisition
