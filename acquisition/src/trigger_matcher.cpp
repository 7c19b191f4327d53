#include "tomorig/acquisition/trigger_matcher.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

constexpr std::size_t kOffsetsKept = 16;
constexpr int kMissesBeforeRelearning = 3;

}  // namespace

TriggerMatcher::TriggerMatcher(int frames_per_trigger, std::int64_t tolerance_ns, std::int64_t burst_separation_ns)
    : frames_per_trigger_(frames_per_trigger), tolerance_ns_(tolerance_ns), burst_separation_ns_(burst_separation_ns) {
  if (burst_separation_ns < 0)
    throw bad_input(fmt::format("trigger matcher: burst separation {} ns must be >= 0", burst_separation_ns));
  if (frames_per_trigger != 1 && frames_per_trigger != 2)
    throw bad_input(fmt::format("trigger matcher: {} frames per trigger; a camera makes 1 or 2", frames_per_trigger));
  if (tolerance_ns <= 0) throw bad_input(fmt::format("trigger matcher: tolerance {} ns must be > 0", tolerance_ns));
}

void TriggerMatcher::expect(const Trigger& trigger) {
  std::lock_guard lock(mutex_);
  pending_.push_back(trigger);
}

std::optional<TriggerMatcher::Match> TriggerMatcher::match(std::uint64_t frame_id, std::int64_t timestamp_ns,
                                                           std::optional<Exposure> burst_position) {
  std::lock_guard lock(mutex_);
  // The counter's parity, corrected once time showed it off by one.
  if (burst_position && parity_flipped_) burst_position = *burst_position == Exposure::A ? Exposure::B : Exposure::A;
  // Frame B of a double-frame camera: the frame right after its trigger's frame A.
  if (open_pair_) {
    const Trigger pair = *open_pair_;
    open_pair_.reset();
    if (frame_id == open_pair_frame_id_ + 1) {
      if (burst_separation_ns_ > 0) {
        // Time decides: B follows A by the burst separation; the next burst's A a period later.
        const bool is_b =
            std::llabs(timestamp_ns - open_pair_timestamp_ns_ - burst_separation_ns_) <= tolerance_ns_;
        if (burst_position && (*burst_position == Exposure::B) != is_b) {
          parity_flipped_ = !parity_flipped_;
          burst_position = is_b ? Exposure::B : Exposure::A;
          // The frame taken for the pair's A was a B: its offset is off by the separation.
          if (!is_b && open_pair_taught_ && !offsets_[0].empty()) offsets_[0].pop_back();
        }
        if (is_b) return Match{pair.event, Exposure::B};
      } else if (burst_position != Exposure::A) {
        return Match{pair.event, Exposure::B};
      }
    }
  }
  const bool lone_b = frames_per_trigger_ == 2 && burst_position == Exposure::B;
  if (pending_.empty()) {
    ++unmatched_;
    return std::nullopt;
  }
  std::size_t best = 0;
  if (!offsets_[0].empty() || !offsets_[1].empty()) {
    auto median = [](const std::deque<std::int64_t>& values) {
      std::vector<std::int64_t> sorted(values.begin(), values.end());
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
      return sorted[sorted.size() / 2];
    };
    // A slot without matches yet borrows the other's offset.
    const std::int64_t offset_a = median(offsets_[0].empty() ? offsets_[1] : offsets_[0]);
    const std::int64_t offset_b = median(offsets_[1].empty() ? offsets_[0] : offsets_[1]);
    // Predictions grow with the trigger times: stop once they are further past the frame
    // than the best so far.
    std::int64_t best_error = std::numeric_limits<std::int64_t>::max();
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      const std::int64_t predicted =
          pending_[i].host_ns + (pending_[i].exposure == Exposure::A ? offset_a : offset_b);
      const std::int64_t error = std::llabs(timestamp_ns - predicted);
      if (error < best_error) {
        best_error = error;
        best = i;
      } else if (predicted > timestamp_ns) {
        break;
      }
    }
    if (best_error > tolerance_ns_) {
      ++unmatched_;
      // Frames that keep fitting no trigger: the camera's clock jumped (a reset). Learn the
      // offset again from the next frame.
      if (++misses_in_a_row_ >= kMissesBeforeRelearning) {
        offsets_[0].clear();
        offsets_[1].clear();
      }
      return std::nullopt;
    }
  }
  // Without an offset yet, a frame answers the oldest trigger: the first frame of the run,
  // or the first after the camera's clock jumped.
  misses_in_a_row_ = 0;
  lost_ += best;
  pending_.erase(pending_.begin(), pending_.begin() + static_cast<std::ptrdiff_t>(best));
  const Trigger hit = pending_.front();
  pending_.pop_front();
  // Frame B whose frame A never came: its trigger, by time (B follows A by far less than the
  // tolerance); it teaches no offset and opens no pair.
  if (lone_b) return Match{hit.event, Exposure::B};
  // A warm-up frame teaches nothing: a camera that is not ready yet answers late.
  if (hit.event) {
    auto& offsets = offsets_[hit.exposure == Exposure::A ? 0 : 1];
    offsets.push_back(timestamp_ns - hit.host_ns);
    if (offsets.size() > kOffsetsKept) offsets.pop_front();
  }
  if (frames_per_trigger_ == 2) {
    open_pair_ = hit;
    open_pair_frame_id_ = frame_id;
    open_pair_timestamp_ns_ = timestamp_ns;
    open_pair_taught_ = hit.event.has_value() && hit.exposure == Exposure::A;
  }
  return Match{hit.event, hit.exposure};
}

void TriggerMatcher::relearn_offsets() {
  std::lock_guard lock(mutex_);
  offsets_[0].clear();
  offsets_[1].clear();
  misses_in_a_row_ = 0;
}

std::uint64_t TriggerMatcher::triggers_lost() const {
  std::lock_guard lock(mutex_);
  return lost_;
}

std::uint64_t TriggerMatcher::frames_unmatched() const {
  std::lock_guard lock(mutex_);
  return unmatched_;
}

}  // namespace tomorig::acquisition
