#include "tomorig/rig/rig_status.h"

#include <unistd.h>

#include <cstdio>

#include <fmt/core.h>
#include <zmq.hpp>

#include "tomorig/rig/rig_acquisition.h"
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
    // A free-running camera's frames are there but not of this event: the set is incomplete.
    const bool unsynchronised = frames != nullptr && ((frames->a.present() && !frames->a.synchronised) ||
                                                      (frames->b.present() && !frames->b.synchronised));
    cameras_[c].frames_lost += static_cast<std::uint64_t>(lost);
    if (lost > 0 || unsynchronised) {
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

std::uint64_t sets_in_flight(std::uint64_t sent, std::uint64_t received) { return sent > received ? sent - received : 0; }

void take_progress(StatusFigures& figures, const RigProgress& progress) {
  figures.dropped_trigger_events = progress.dropped_trigger_events;
  figures.trigger_lag_events = progress.trigger_queue;
  figures.trigger_queue_capacity = progress.trigger_queue_capacity;
  figures.trigger_rate_hz = progress.rate_hz;
  figures.cameras.clear();
  for (std::size_t c = 0; c < progress.cameras.size(); ++c) {
    const CameraHealth& h = progress.cameras[c];
    CameraFigures f;
    f.id = h.id;
    f.connected = h.connected;
    f.problem = h.problem;
    f.free_running = h.free_running;
    f.frames = h.stream.delivered;
    f.underruns = h.stream.underruns;
    f.failed = h.stream.failures;
    f.missing_packets = h.stream.missing_packets;
    f.resends = h.stream.resends;
    if (c < progress.assembly.cameras.size()) f.mismatched = progress.assembly.cameras[c].frames_mismatched;
    figures.cameras.push_back(std::move(f));
  }
}

std::vector<std::string> StatusReporter::warnings(const StatusFigures& f, double minutes_until_full) {
  std::vector<std::string> out;
  for (const auto& c : f.cameras)
    if (!c.connected)
      out.push_back(fmt::format("camera {} disconnected{}", c.id, c.problem.empty() ? "" : ": " + c.problem));
  std::string free_running;
  for (const auto& c : f.cameras)
    if (c.free_running) free_running += (free_running.empty() ? "" : ", ") + c.id;
  if (!free_running.empty())
    out.push_back(fmt::format("free-running camera{} {}: frames not synchronised with the trigger, no set is complete",
                              free_running.find(',') == std::string::npos ? "" : "s", free_running));
  if (f.trigger_queue_capacity > 0 &&
      static_cast<double>(f.trigger_lag_events) >= kLagWarningFraction * static_cast<double>(f.trigger_queue_capacity))
    out.push_back(fmt::format("the rig lags the trigger by {} events ({:.0f} ms); trigger events are dropped at {}",
                              f.trigger_lag_events,
                              f.trigger_rate_hz > 0 ? 1e3 * static_cast<double>(f.trigger_lag_events) / f.trigger_rate_hz
                                                    : 0.0,
                              f.trigger_queue_capacity));
  if (f.dropped_trigger_events > 0) out.push_back(fmt::format("{} trigger events dropped", f.dropped_trigger_events));
  if (minutes_until_full >= 0.0 && minutes_until_full < 10.0)
    out.push_back(fmt::format("the disk is full in {:.1f} min at this rate", minutes_until_full));
  return out;
}

std::string StatusReporter::line(const StatusFigures& f, const LossTally& losses, double minutes_until_full) const {
  std::string text = fmt::format("{}: set {}{}  {:.1f} sets/s  {:.1f} MB/s  queue {}  lost frames/incomplete sets: {}",
                                 label_, f.sets, f.total ? fmt::format("/{}", *f.total) : std::string(),
                                 sets_per_second_, mb_per_second_, f.queue_depth, losses.per_camera());
  const double lag_ms =
      f.trigger_rate_hz > 0 ? 1e3 * static_cast<double>(f.trigger_lag_events) / f.trigger_rate_hz : 0.0;
  text += fmt::format("  trigger: lag {} events ({:.0f} ms) of {}, dropped {}", f.trigger_lag_events, lag_ms,
                      f.trigger_queue_capacity, f.dropped_trigger_events);
  if (f.disk_free_bytes)
    text += fmt::format("  disk: {:.1f} GB free, {}", static_cast<double>(*f.disk_free_bytes) / 1e9,
                        minutes_until_full >= 0 ? fmt::format("{:.0f} min to full", minutes_until_full)
                                                : std::string("time to full unknown"));
  if (!f.cameras.empty()) {
    text += "  cameras:";
    for (std::size_t c = 0; c < f.cameras.size(); ++c) {
      const auto& cam = f.cameras[c];
      text += fmt::format("{} {} {}{} {} frames, underruns {}, failed {}, missing packets {}, resends {}, mismatched {}",
                          c == 0 ? "" : ";", cam.id, cam.connected ? "connected" : "DISCONNECTED",
                          cam.free_running ? " free-running" : "", cam.frames, cam.underruns, cam.failed,
                          cam.missing_packets, cam.resends, cam.mismatched);
    }
  }
  for (const auto& w : warnings(f, minutes_until_full)) text += "  WARNING " + w;
  return text;
}

stream::Status StatusReporter::message(const StatusFigures& f, const LossTally& losses, double minutes_until_full) const {
  stream::Status s;
  s.time_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  s.state = f.state;
  s.sets_total = f.sets;
  s.sets_per_second = sets_per_second_;
  (f.to_disk ? s.disk_mb_per_second : s.stream_mb_per_second) = mb_per_second_;
  s.frames_lost = losses.frames_lost();
  s.incomplete_sets = losses.incomplete_sets();
  s.queue_depth = f.queue_depth;
  s.dropped_trigger_events = f.dropped_trigger_events;
  s.trigger_lag_events = f.trigger_lag_events;
  s.trigger_lag_ms = f.trigger_rate_hz > 0 ? 1e3 * static_cast<double>(f.trigger_lag_events) / f.trigger_rate_hz : 0.0;
  s.trigger_queue_capacity = f.trigger_queue_capacity;
  if (f.disk_free_bytes) s.disk_free_bytes = static_cast<std::int64_t>(*f.disk_free_bytes);
  s.disk_minutes_until_full = minutes_until_full;
  s.warnings = warnings(f, minutes_until_full);
  for (const auto& c : losses.cameras()) {
    stream::CameraStatus cam;
    cam.camera_id = c.id;
    cam.frames_lost = c.frames_lost;
    cam.incomplete_sets = c.incomplete_sets;
    for (const auto& h : f.cameras) {
      if (h.id != c.id) continue;
      cam.connected = h.connected;
      cam.problem = h.problem;
      cam.free_running = h.free_running;
      cam.frames = h.frames;
      cam.underruns = h.underruns;
      cam.failed = h.failed;
      cam.missing_packets = h.missing_packets;
      cam.resends = h.resends;
      cam.mismatched = h.mismatched;
    }
    s.cameras.push_back(std::move(cam));
  }
  return s;
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
  std::string health;  // a camera lost or back shows at once, not up to a second later
  for (const auto& c : f.cameras) health += c.connected ? '1' : '0';
  const bool due = final || new_early_set || health != printed_health_ || since_print >= (tty_ ? 0.25 : 1.0);
  if (!due) return;
  printed_sets_ = f.sets;
  printed_health_ = health;
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

  // Minutes until the disk is full at the current write rate (unknown until data flows).
  double minutes_until_full = -1.0;
  if (f.disk_free_bytes && mb_per_second_ > 0.0)
    minutes_until_full = static_cast<double>(*f.disk_free_bytes) / (mb_per_second_ * 1e6) / 60.0;

  const std::string text = line(f, losses, minutes_until_full);
  if (tty_ && !final) {
    fmt::print(stderr, "\r{}   ", text);
    line_open_ = true;
  } else {
    fmt::print(stderr, "{}{}\n", tty_ ? "\r" : "", text);
    line_open_ = false;
  }
  std::fflush(stderr);

  if (publisher_) publisher_->publish(message(f, losses, minutes_until_full));  // latest-wins: a full subscriber misses it
}

void StatusReporter::break_line() {
  if (!line_open_) return;
  fmt::print(stderr, "\n");
  line_open_ = false;
}

}  // namespace tomorig::rig
