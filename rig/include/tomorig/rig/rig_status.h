#pragma once
// The live status of a running rig (tomorig run, tomorig acquire): one line on stderr,
// rewritten in place on a terminal, and the same figures as JSON on the status PUB socket
// (docs/wire-protocol.md, "Status messages"; docs/acquisition.md lists the fields).
//
//   recording: set 12/500  9.9 sets/s  41.9 MB/s  queue 1  lost frames/incomplete sets: cam0 0/0 cam1 2/1
//     trigger: lag 0 events (0 ms) of 256, dropped 0  disk: 812.4 GB free, 331 min to full
//     cameras: cam0 connected 24 frames, underruns 0, failed 0, missing packets 0, resends 0, mismatched 0; ...
//     WARNING ...
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"

namespace zmq {
class context_t;
}
namespace tomorig::stream {
class StatusPublisher;
struct Status;
}

namespace tomorig::rig {

// Losses as the sets show them, per camera: empty frames, and sets with at least one of the
// camera's frames missing.
class LossTally {
 public:
  struct Camera {
    std::string id;
    std::uint64_t frames_lost = 0;
    std::uint64_t incomplete_sets = 0;
  };
  explicit LossTally(const std::vector<std::string>& camera_ids);
  // Counts the missing frames of `set` (cameras matched by id; a camera absent from the set
  // loses both frames).
  void add(const FrameSet& set);
  std::uint64_t frames_lost() const;
  std::uint64_t incomplete_sets() const { return incomplete_sets_; }  // sets missing a frame or unsynchronised
  const std::vector<Camera>& cameras() const { return cameras_; }
  // "cam0 0/0 cam1 2/1" (lost frames / incomplete sets)
  std::string per_camera() const;

 private:
  std::vector<Camera> cameras_;
  std::uint64_t incomplete_sets_ = 0;
};

struct RigProgress;

// One camera as the status shows it (the losses its sets show come from LossTally).
struct CameraFigures {
  std::string id;
  bool connected = true;
  std::string problem;        // why not connected
  bool free_running = false;
  std::uint64_t frames = 0;   // delivered by the camera
  std::uint64_t underruns = 0, failed = 0, missing_packets = 0, resends = 0;  // Aravis stream counters
  std::uint64_t mismatched = 0;  // frames dropped because B - A disagreed with the plan
};

struct StatusFigures {
  std::string state = "running";     // running, stopping, stopped, failed
  std::uint64_t sets = 0;             // sets done (recorded, or sent)
  std::optional<std::uint64_t> total; // sets asked for
  std::uint64_t bytes = 0;            // pixel bytes done
  std::uint64_t queue_depth = 0;      // sets between acquisition and the recorder
  std::uint64_t dropped_trigger_events = 0;
  std::uint64_t trigger_lag_events = 0;      // events fired and not yet handled
  std::uint64_t trigger_queue_capacity = 0;  // a paced trigger drops events beyond this lag
  double trigger_rate_hz = 0.0;
  std::optional<std::uint64_t> disk_free_bytes;  // where the recording goes (to_disk only)
  bool to_disk = true;                // bytes went to disk (run, record) or to the stream (acquire)
  std::vector<CameraFigures> cameras;
};

// Copies the rig's snapshot (trigger lag and drops, camera health and stream counters) into
// the figures.
void take_progress(StatusFigures& figures, const RigProgress& progress);

// Sets between two counters that are read one after the other while both move: the receiver
// may already count a set the sender's counter does not show yet. Never below zero.
std::uint64_t sets_in_flight(std::uint64_t sent, std::uint64_t received);

// A trigger lag this deep (of the queue's capacity) is warned about before events drop.
inline constexpr double kLagWarningFraction = 0.25;

class StatusReporter {
 public:
  // `label` starts the line ("recording", "acquire"). `status_endpoint`: where the JSON status
  // PUB socket binds; empty or "none": no socket. A socket that cannot bind is reported on
  // stderr and left out; the run goes on.
  StatusReporter(std::string label, zmq::context_t& context, const std::string& status_endpoint);
  ~StatusReporter();
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

  // The endpoint the status socket is bound to, or "" if none.
  std::string endpoint() const;

  // Prints (and publishes) when due: every set for the first few, then at most 4 times a
  // second on a terminal and once a second otherwise; `final` always prints, with the whole
  // run's average rates, and ends the line.
  void update(const StatusFigures& figures, const LossTally& losses, bool final = false);
  // Ends a status line rewritten in place, so other messages start on a fresh line.
  void break_line();

  // The status as text (the line) and as the JSON status message: the same figures.
  std::string line(const StatusFigures& figures, const LossTally& losses, double minutes_until_full) const;
  stream::Status message(const StatusFigures& figures, const LossTally& losses, double minutes_until_full) const;
  // What needs the operator: a lost camera, free-running cameras, a lagging trigger, a disk
  // about to fill. On every status line while it lasts.
  static std::vector<std::string> warnings(const StatusFigures& figures, double minutes_until_full);

 private:
  std::string label_;
  bool tty_;
  std::unique_ptr<stream::StatusPublisher> publisher_;
  std::chrono::steady_clock::time_point started_;
  std::chrono::steady_clock::time_point last_print_;
  std::chrono::steady_clock::time_point last_rate_;
  std::uint64_t rate_sets_ = 0;
  std::uint64_t rate_bytes_ = 0;
  double sets_per_second_ = 0.0;
  double mb_per_second_ = 0.0;
  bool line_open_ = false;
  std::uint64_t printed_sets_ = ~std::uint64_t{0};  // sets shown by the last line
  std::string printed_health_;                      // cameras' connected flags on the last line
};

}  // namespace tomorig::rig
