#include "tomorig/rig/stream_session.h"

#include <fmt/core.h>

#include "tomorig/rig/record_layout.h"

namespace tomorig::rig {
namespace {

// Truth messages waiting for their set: the sender sends each just before its set, so more
// than a handful only pile up if sets were refused or lost.
constexpr std::size_t kHeldTruth = 64;

}  // namespace

StreamSession::StartOutcome StreamSession::on_start(stream::SessionStart start, bool recording) {
  if (announced_ && announced_->session_id == start.session_id) return StartOutcome::repeated;
  if (recording) return StartOutcome::conflict;
  // No file yet: a sender that restarted before the file was opened simply replaces the
  // announcement.
  announced_ = std::move(start);
  ended_.reset();
  truth_.clear();
  return StartOutcome::adopted;
}

void StreamSession::on_truth(stream::SetTruth truth) {
  if (!announced_ || truth.session_id != announced_->session_id) return;
  truth_[truth.trigger_index] = std::move(truth.particles);
  while (truth_.size() > kHeldTruth) truth_.erase(truth_.begin());
}

bool StreamSession::on_end(const stream::SessionEnd& end) {
  if (!announced_ || end.session_id != announced_->session_id) return false;
  ended_ = end;
  return true;
}

std::optional<std::vector<storage::SessionCamera>> StreamSession::cameras_known_in_advance() const {
  if (!announced_) return std::nullopt;
  for (const auto& cam : announced_->info.cameras)
    if (cam.width <= 0 || cam.height <= 0) return std::nullopt;
  return announced_->info.cameras;
}

std::optional<std::vector<storage::SessionCamera>> StreamSession::cameras_from_first_set(const FrameSet& set,
                                                                                       std::string& why) const {
  if (announced_) return complete_announced_cameras(announced_->info.cameras, set, why);
  return cameras_from_set(set, why);
}

storage::SessionInfo StreamSession::file_info(std::vector<storage::SessionCamera> cameras,
                                              const std::string& source) const {
  storage::SessionInfo info;
  if (announced_) {
    info = announced_->info;  // rig config, software version and creation time as the sender gave them
  } else {
    info.rig_config_toml = fmt::format(
        "# recorded by 'tomorig record' from {}; the sender announced no session (an older tomorig), so the rig "
        "configuration is unknown\n",
        source);
  }
  info.cameras = std::move(cameras);
  return info;
}

std::optional<storage::TruthSet> StreamSession::take_truth(std::uint64_t trigger_index) {
  const auto it = truth_.find(trigger_index);
  if (it == truth_.end()) return std::nullopt;
  storage::TruthSet truth = std::move(it->second);
  truth_.erase(it);
  return truth;
}

}  // namespace tomorig::rig
