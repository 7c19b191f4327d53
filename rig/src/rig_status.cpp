#include "tomorig/rig/rig_status.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/core/error.h"
#include "tomorig/stream/status.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;

// The first sets are always printed, so a short run (and a test waiting for "set 3/") sees
// each of them; after that the line is rate-limited.
constexpr std::uint64_t kAlwaysPrintedSets = 10;

}  // namespace

LossTally::LossTally(const std::vector<std::string>& camera_ids) {
  for (const auto& id : camera_ids) cameras_.push_back({id, 0, 0});
}

void LossTally::add(const FrameSet& set) {
  bool incomplete = false;
  for (std::size_t c = 0; c < cameras_.size(); ++c) {
    const CameraFrames* frames = c < set.cameras.size() && set.cameras[c].camera_id == cameras_[c].id
                                     ? &set.cameras[c]
                                     : nullptr;
    if (frames == nullptr)
      for (const auto& f : set.cameras)
        if (f.camera_id == cameras_[c].id) frames = &f;
    const int lost = frames == nullptr ? 2 : (frames->a.present() ? 0 : 1) + (frames->b.present() ? 0 : 1);
    cameras_[c].frames_lost += static_cast<std::uint64_t>(lost);
    if (lost > 0) {
      ++cameras_[c].incomplete_sets;
      incomplete = true;
    }
  }
  if (incomplete) ++incomplete_sets_;
}

std::uint64_t LossTally::frames_lost() const {
  std::uint64_t n = 0;
  for (const auto& c : cameras_) n += c.frames_lost;
  return n;
}

std::string LossTally::per_camera() const {
  std::string text;
  for (const auto& c : cameras_)
    text += fmt::format("{}{} {}/{}", text.empty() ? "" : " ", c.id, c.frames_lost, c.incomplete_sets);
  return text;
}

StatusReporter::StatusReporter(std::string label, zmq::context_t& context, const std::string& status_endpoint)
    : label_(std::move(label)), tty_(isatty(STDERR_FILENO) == 1), started_(Clock::now()), last_print_(Clock::now()), last_rate_(Clock::now()) {
  if (status_endpoint.empty() || status_endpoint == "none") return;
  try {
    publisher_ = std::make_unique<stream::StatusPublisher>(context, stream::status_socket_options(status_endpoint));
  } catch (const Error& e) {
    if (e.kind() == ErrorKind::bad_input) throw;  // a refused address is the operator's to fix
    fmt::print(stderr, "{}: no status socket ({}); going on without it, choose another --status\n", label_,
               e.what());
  }
}

StatusReporter::~StatusReporter() = default;

std::string StatusReporter::endpoint() const { return publisher_ ? publisher_->endpoint() : std::string(); }

void StatusReporter::update(const StatusFigures& f, const LossTally& losses, bool final) {
  const auto now = Clock::now();
  const double since_print = std::chrono::duration<double>(now - last_print_).count();
  const bool new_early_set = f.sets <= kAlwaysPrintedSets && f.sets != printed_sets_;
  const bool due = final || new_early_set || since_print >= (tty_ ? 0.25 : 1.0);
  if (!due) return;
  printed_sets_ = f.sets;
  const double since_rate = std::chrono::duration<double>(now - last_rate_).count();
  if (final) {
    // The closing line gives the whole run's averages.
    const double run_seconds = std::chrono::duration<double>(now - started_).count();
    if (run_seconds > 0) {
      sets_per_second_ = static_cast<double>(f.sets) / run_seconds;
      mb_per_second_ = static_cast<double>(f.bytes) / run_seconds / 1e6;
    }
  } else if (since_rate >= 0.5) {
    sets_per_second_ = static_cast<double>(f.sets - rate_sets_) / since_rate;
    mb_per_second_ = static_cast<double>(f.bytes - rate_bytes_) / since_rate / 1e6;
    last_rate_ = now;
    rate_sets_ = f.sets;
    rate_bytes_ = f.bytes;
  }
  last_print_ = now;

  std::string line = fmt::format("{}: set {}{}  {:.1f} sets/s  {:.1f} MB/s  queue {}  lost frames/incomplete sets: {}",
                                 label_, f.sets, f.total ? fmt::format("/{}", *f.total) : std::string(),
                                 sets_per_second_, mb_per_second_, f.queue_depth, losses.per_camera());
  if (f.dropped_trigger_events > 0) line += fmt::format("  trigger events dropped {}", f.dropped_trigger_events);
  if (tty_ && !final) {
    fmt::print(stderr, "\r{}   ", line);
    line_open_ = true;
  } else {
    fmt::print(stderr, "{}{}\n", tty_ ? "\r" : "", line);
    line_open_ = false;
  }
  std::fflush(stderr);

  if (publisher_) {
    stream::Status s;
    s.time_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
    s.state = f.state;
    s.sets_total = f.sets;
    s.sets_per_second = sets_per_second_;
    (f.to_disk ? s.disk_mb_per_second : s.stream_mb_per_second) = mb_per_second_;
    s.frames_lost = losses.frames_lost();
    s.incomplete_sets = losses.incomplete_sets();
    s.queue_depth = f.queue_depth;
    for (const auto& c : losses.cameras()) s.cameras.push_back({c.id, c.frames_lost, c.incomplete_sets});
    publisher_->publish(s);  // latest-wins: a full subscriber just misses this update
  }
}

void StatusReporter::break_line() {
  if (!line_open_) return;
  fmt::print(stderr, "\n");
  line_open_ = false;
}

}  // namespace tomorig::rig
