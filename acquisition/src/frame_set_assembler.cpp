#include "tomorig/acquisition/frame_set_assembler.h"

#include <fmt/format.h>

#include <cstdlib>
#include <set>
#include <utility>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

std::int64_t steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

void AssemblerOptions::validate() const {
  if (camera_ids.empty()) throw bad_input("assembler camera_ids is empty: give at least one camera");
  std::set<std::string> seen;
  for (const auto& id : camera_ids)
    if (!seen.insert(id).second)
      throw bad_input(fmt::format("assembler camera_ids lists '{}' twice: camera ids must be unique", id));
  if (timeout.count() <= 0)
    throw bad_input(fmt::format("assembler timeout = {} ns: must be > 0", timeout.count()));
  if (max_index_jump == 0) throw bad_input("assembler max_index_jump = 0: must be > 0");
  if (max_queued_sets == 0) throw bad_input("assembler max_queued_sets = 0: must be > 0");
  if (!pairing.empty() && pairing.size() != camera_ids.size())
    throw bad_input(fmt::format("assembler pairing lists {} cameras but camera_ids {}: give one entry per camera or none",
                                pairing.size(), camera_ids.size()));
  for (std::size_t c = 0; c < pairing.size(); ++c)
    if (pairing[c].tolerance_ns < 0)
      throw bad_input(fmt::format("assembler pairing of {}: tolerance {} ns must be >= 0", camera_ids[c],
                                  pairing[c].tolerance_ns));
}

const AssemblerOptions::CameraPairing* FrameSetAssembler::pairing_of(std::size_t camera) const {
  return camera < options_.pairing.size() ? &options_.pairing[camera] : nullptr;
}

FrameSetAssembler::FrameSetAssembler(AssemblerOptions options, AssemblyClock clock)
    : options_(std::move(options)), clock_(clock ? std::move(clock) : AssemblyClock(steady_now_ns)) {
  options_.validate();
  next_index_ = options_.first_trigger_index;
  for (const auto& id : options_.camera_ids) stats_.cameras.push_back(CameraLoss{id});
}

bool FrameSetAssembler::accept_index_locked(std::uint64_t index) {
  if (!next_index_) next_index_ = index;
  if (index < *next_index_) return false;  // its set has been emitted already
  return true;
}

bool FrameSetAssembler::ready_locked(const Pending& p) const {
  for (std::size_t c = 0; c < p.set.cameras.size(); ++c) {
    if (stats_.cameras[c].lost) continue;  // nothing more will come from it
    if (!p.set.cameras[c].a.present() || !p.set.cameras[c].b.present()) return false;
  }
  return true;
}

void FrameSetAssembler::place_locked(std::size_t camera, Pending& p, CameraFrame&& frame) {
  CameraLoss& loss = stats_.cameras[camera];
  Frame& slot = p.set.cameras[camera][frame.exposure];
  if (slot.present()) {
    ++loss.frames_duplicate;
    return;
  }
  ++loss.frames_received;
  slot.image = std::move(frame.image);
  slot.timestamp_ns = frame.timestamp_ns;
  const auto* pairing = pairing_of(camera);
  slot.synchronised = pairing == nullptr || !pairing->free_running;
  if (!p.trigger_known && !p.frame_timing_known && frame.trigger_timestamp_ns != 0) {
    p.set.trigger_timestamp_ns = frame.trigger_timestamp_ns;
    p.set.dt_ns = frame.dt_ns;
    p.frame_timing_known = true;
  }
}

void FrameSetAssembler::place_free_running_locked(std::size_t camera, CameraFrame&& frame) {
  const std::int64_t arrived = clock_();
  for (auto& [index, p] : pending_) {
    if (!p.trigger_known || p.announced_ns > arrived) continue;  // the event had not happened yet
    CameraFrames& slots = p.set.cameras[camera];
    if (slots.a.present() && slots.b.present()) continue;
    frame.trigger_index = index;
    frame.exposure = slots.a.present() ? Exposure::B : Exposure::A;
    place_locked(camera, p, std::move(frame));
    return;
  }
  ++stats_.cameras[camera].frames_surplus;
}

// Frames A and B of one camera belong to one trigger event only if their timestamps are as
// far apart as the plan puts the two frames. Anything else (B − A a whole period, or negative)
// means the camera skipped or added a frame and the pair straddles two events: both go.
void FrameSetAssembler::check_pairs_locked(FrameSet& set) {
  for (std::size_t c = 0; c < set.cameras.size(); ++c) {
    const auto* pairing = pairing_of(c);
    if (pairing == nullptr || pairing->tolerance_ns <= 0 || pairing->free_running) continue;
    CameraFrames& frames = set.cameras[c];
    if (!frames.a.present() || !frames.b.present() || frames.a.timestamp_ns == 0 || frames.b.timestamp_ns == 0)
      continue;
    const std::int64_t separation = frames.b.timestamp_ns - frames.a.timestamp_ns;
    if (std::llabs(separation - pairing->expected_separation_ns) <= pairing->tolerance_ns) continue;
    CameraLoss& loss = stats_.cameras[c];
    loss.frames_mismatched += 2;
    loss.frames_received -= 2;  // counted again as missing below: the set never holds them
    loss.last_mismatch = fmt::format(
        "set of trigger {}: frames A and B of {} are {:.3f} ms apart by the camera's clock, the plan says {:.3f} ms "
        "± {:.3f} ms, so they came from different trigger events; both dropped, the set is incomplete",
        set.trigger_index, loss.camera_id, static_cast<double>(separation) / 1e6,
        static_cast<double>(pairing->expected_separation_ns) / 1e6, static_cast<double>(pairing->tolerance_ns) / 1e6);
    frames.a = Frame{};
    frames.b = Frame{};
  }
}

void FrameSetAssembler::mark_camera_lost(std::size_t camera) {
  std::unique_lock lock(mutex_);
  if (camera >= stats_.cameras.size()) return;
  stats_.cameras[camera].lost = true;
  expire_locked(lock, clock_());
}

FrameSetAssembler::Pending& FrameSetAssembler::pending_for_locked(std::uint64_t index, std::int64_t now) {
  auto found = pending_.find(index);
  if (found != pending_.end()) return found->second;
  // Every index between the newest pending set (or the next to emit) and this one is a set
  // whose frames have not arrived yet: create it now, so it times out and is reported
  // (all frames missing) instead of vanishing from the sequence.
  std::uint64_t first_new = pending_.empty() ? *next_index_ : pending_.rbegin()->first + 1;
  if (index < first_new) first_new = index;
  for (std::uint64_t k = first_new; k <= index; ++k) {
    if (pending_.count(k)) continue;
    Pending p;
    p.set.trigger_index = k;
    p.set.cameras.resize(options_.camera_ids.size());
    for (std::size_t c = 0; c < options_.camera_ids.size(); ++c) p.set.cameras[c].camera_id = options_.camera_ids[c];
    p.deadline_ns = now + options_.timeout.count();
    pending_.emplace(k, std::move(p));
  }
  return pending_.at(index);
}

void FrameSetAssembler::add_frame(std::size_t camera, CameraFrame frame) {
  std::unique_lock lock(mutex_);
  // Back-pressure: the consumer is behind; wait rather than drop.
  drained_.wait(lock, [&] { return queue_.size() < options_.max_queued_sets; });
  const std::int64_t now = clock_();
  if (camera >= options_.camera_ids.size() || frame.image.empty()) {
    ++stats_.frames_rejected;
    expire_locked(lock, now);
    return;
  }
  CameraLoss& loss = stats_.cameras[camera];
  const auto* pairing = pairing_of(camera);
  if (pairing != nullptr && pairing->free_running) {
    place_free_running_locked(camera, std::move(frame));
    expire_locked(lock, now);
    return;
  }
  if (options_.end_trigger_index && frame.trigger_index >= *options_.end_trigger_index) {
    ++loss.frames_beyond_run;
    expire_locked(lock, now);
    return;
  }
  if (!accept_index_locked(frame.trigger_index)) {
    ++loss.frames_late;
    expire_locked(lock, now);
    return;
  }
  const std::uint64_t horizon = pending_.empty() ? *next_index_ : pending_.begin()->first;
  if (frame.trigger_index - horizon > options_.max_index_jump) {
    ++stats_.frames_rejected;
    expire_locked(lock, now);
    return;
  }
  place_locked(camera, pending_for_locked(frame.trigger_index, now), std::move(frame));
  expire_locked(lock, now);
}

void FrameSetAssembler::add_trigger(const TriggerInput& trigger) {
  std::unique_lock lock(mutex_);
  const std::int64_t now = clock_();
  const bool in_run = !options_.end_trigger_index || trigger.index < *options_.end_trigger_index;
  if (in_run && accept_index_locked(trigger.index)) {
    const std::uint64_t horizon = pending_.empty() ? *next_index_ : pending_.begin()->first;
    if (trigger.index - horizon <= options_.max_index_jump) {
      Pending& p = pending_for_locked(trigger.index, now);
      p.set.trigger_timestamp_ns = trigger.timestamp_ns;
      p.set.dt_ns = trigger.dt_ns;
      p.trigger_known = true;
      p.announced_ns = now;
    }
  }
  expire_locked(lock, now);
}

void FrameSetAssembler::emit_front_locked(std::unique_lock<std::mutex>&) {
  auto front = pending_.begin();
  Pending p = std::move(front->second);
  pending_.erase(front);
  next_index_ = p.set.trigger_index + 1;

  FrameSet& set = p.set;
  // Without a trigger the set's time stays 0 (unknown): trigger_timestamp_ns is on the
  // trigger clock in every set, never a camera's clock.
  check_pairs_locked(set);
  set.set_index = next_set_index_++;
  for (std::size_t c = 0; c < set.cameras.size(); ++c)
    stats_.cameras[c].frames_missing += (set.cameras[c].a.present() ? 0 : 1) + (set.cameras[c].b.present() ? 0 : 1);
  ++stats_.sets_emitted;
  if (set.complete()) ++stats_.sets_complete;
  else ++stats_.sets_incomplete;
  queue_.push_back(std::move(set));
  ready_.notify_all();
}

void FrameSetAssembler::expire_locked(std::unique_lock<std::mutex>& lock, std::int64_t now) {
  while (!pending_.empty()) {
    const Pending& front = pending_.begin()->second;
    if (!ready_locked(front) && front.deadline_ns > now) break;
    emit_front_locked(lock);
  }
}

void FrameSetAssembler::expire() {
  std::unique_lock lock(mutex_);
  expire_locked(lock, clock_());
}

void FrameSetAssembler::flush() {
  std::unique_lock lock(mutex_);
  while (!pending_.empty()) emit_front_locked(lock);
}

std::optional<FrameSet> FrameSetAssembler::try_pop() {
  std::unique_lock lock(mutex_);
  expire_locked(lock, clock_());
  if (queue_.empty()) return std::nullopt;
  FrameSet set = std::move(queue_.front());
  queue_.pop_front();
  drained_.notify_all();
  return set;
}

std::optional<FrameSet> FrameSetAssembler::pop(std::chrono::milliseconds wait) {
  const auto give_up = std::chrono::steady_clock::now() + wait;
  std::unique_lock lock(mutex_);
  for (;;) {
    expire_locked(lock, clock_());
    if (!queue_.empty()) break;
    const auto real_now = std::chrono::steady_clock::now();
    if (real_now >= give_up) return std::nullopt;
    // Wake up for the next set or the oldest pending deadline, whichever comes first.
    auto until = give_up;
    if (!pending_.empty()) {
      const auto left = std::chrono::nanoseconds(pending_.begin()->second.deadline_ns - clock_());
      if (real_now + left < until) until = real_now + std::max(left, std::chrono::nanoseconds(0));
    }
    ready_.wait_until(lock, until);
  }
  FrameSet set = std::move(queue_.front());
  queue_.pop_front();
  drained_.notify_all();
  return set;
}

std::size_t FrameSetAssembler::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::size_t FrameSetAssembler::pending() const {
  std::lock_guard lock(mutex_);
  return pending_.size();
}

AssemblyStatistics FrameSetAssembler::statistics() const {
  std::lock_guard lock(mutex_);
  return stats_;
}

}  // namespace tomorig::acquisition
