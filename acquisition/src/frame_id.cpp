#include "tomorig/acquisition/frame_id.h"

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {

FrameIdUnwrapper::FrameIdUnwrapper(int bits, bool zero_reserved) : zero_reserved_(zero_reserved) {
  if (bits < 2 || bits > 63)
    throw bad_input(fmt::format("frame id width {} bits is invalid: must be in [2, 63]", bits));
  mask_ = (std::uint64_t{1} << bits) - 1;
  cycle_ = mask_ + 1 - (zero_reserved ? 1 : 0);
}

std::uint64_t FrameIdUnwrapper::position(std::uint64_t raw) const {
  raw &= mask_;
  if (!zero_reserved_) return raw;
  // 1..max map to 0..cycle-1; a 0 (should not happen) is treated as the slot after max.
  return raw == 0 ? 0 : raw - 1;
}

void FrameIdUnwrapper::expect_first(std::uint64_t raw) {
  // Pretend the frame just before `raw` was seen as sequence -1 (unsigned wrap: the next
  // sequence number, last + 1, is 0).
  started_ = true;
  last_position_ = (position(raw) + cycle_ - 1) % cycle_;
  last_sequence_ = ~std::uint64_t{0};
  gaps_ = 0;
}

std::optional<std::uint64_t> FrameIdUnwrapper::unwrap(std::uint64_t raw) {
  const std::uint64_t pos = position(raw);
  if (!started_) {
    started_ = true;
    last_position_ = pos;
    last_sequence_ = 0;
    return 0;
  }
  // Forward distance around the cycle; more than half a cycle forward is read as a frame
  // from the past (stale or duplicated) rather than a huge loss.
  const std::uint64_t forward = (pos + cycle_ - last_position_) % cycle_;
  if (forward == 0 || forward > cycle_ / 2) return std::nullopt;
  gaps_ += forward - 1;
  last_position_ = pos;
  last_sequence_ += forward;
  return last_sequence_;
}

}  // namespace tomorig::acquisition
