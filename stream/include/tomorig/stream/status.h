#pragma once
// The status stream: one JSON object per message on a PUB socket, for a status line, a GUI or
// a monitoring script (fields: docs/wire-protocol.md, "Status messages"). Status is
// latest-wins, so publishing never waits and a slow subscriber simply misses updates.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/stream/endpoint.h"

namespace zmq {
class context_t;
}

namespace tomorig::stream {

inline constexpr int kStatusVersion = 1;

struct CameraStatus {
  std::string camera_id;
  std::uint64_t frames_lost = 0;
  std::uint64_t incomplete_sets = 0;
  bool connected = true;
  std::string problem;              // why it is not connected; empty while it is
  bool free_running = false;        // frame_mode "free_run": unsynchronised, sets never complete
  std::uint64_t frames = 0;         // frames the camera delivered
  std::uint64_t underruns = 0;      // Aravis stream: frames dropped for want of a buffer
  std::uint64_t failed = 0;         // Aravis stream: incomplete or unusable frames
  std::uint64_t missing_packets = 0;  // GigE Vision packets never received
  std::uint64_t resends = 0;          // GigE Vision packets received after a resend request
  std::uint64_t mismatched = 0;       // frames dropped because B - A disagreed with the plan

  bool operator==(const CameraStatus&) const = default;
};

struct Status {
  std::int64_t time_ns = 0;         // when the figures were taken (system clock)
  std::string state = "running";    // e.g. starting, running, stopping, stopped, failed
  std::uint64_t sets_total = 0;
  double sets_per_second = 0.0;
  double stream_mb_per_second = 0.0;
  std::uint64_t frames_lost = 0;
  std::uint64_t incomplete_sets = 0;
  std::uint64_t preview_drops = 0;
  std::uint64_t queue_depth = 0;    // sets waiting between acquisition and recorder
  double disk_mb_per_second = 0.0;
  std::uint64_t dropped_trigger_events = 0;  // events the trigger fired while the rig lagged
  std::uint64_t trigger_lag_events = 0;      // events fired and not yet handled
  double trigger_lag_ms = 0.0;               // the same as time: events / rate
  std::uint64_t trigger_queue_capacity = 0;  // events are dropped once the lag reaches this
  std::int64_t disk_free_bytes = -1;         // -1: not recording to disk
  double disk_minutes_until_full = -1.0;     // at the current write rate; -1: unknown
  std::vector<std::string> warnings;         // what the operator must look at, as on the status line
  std::vector<CameraStatus> cameras;

  bool operator==(const Status&) const = default;
};

std::string to_json(const Status& status);
// Throws bad_input naming the problem (not JSON, wrong type or version, missing or mistyped key).
Status parse_status(std::string_view json);

// Status defaults: one queued update is enough, nobody waits.
inline SocketOptions status_socket_options(std::string address) {
  SocketOptions o;
  o.endpoint.address = std::move(address);
  o.high_water_mark = 4;
  o.timeout = std::chrono::milliseconds(1000);
  return o;
}

class StatusPublisher {
 public:
  StatusPublisher(zmq::context_t& context, SocketOptions options);
  ~StatusPublisher();
  StatusPublisher(const StatusPublisher&) = delete;
  StatusPublisher& operator=(const StatusPublisher&) = delete;

  // False if a subscriber was full and this update was dropped.
  bool publish(const Status& status);
  const std::string& endpoint() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class StatusSubscriber {
 public:
  StatusSubscriber(zmq::context_t& context, SocketOptions options);
  ~StatusSubscriber();
  StatusSubscriber(const StatusSubscriber&) = delete;
  StatusSubscriber& operator=(const StatusSubscriber&) = delete;

  // The next update, or nullopt after options.timeout (publisher gone or quiet).
  std::optional<Status> receive();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::stream
