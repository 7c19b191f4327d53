#pragma once
// The preview path (ZeroMQ PUB/SUB): quick-look consumers get the newest sets, or the newest
// quick-look results (JSON plus small images), they can keep up with. The publisher never
// waits: when a subscriber's queue is full the message is dropped and counted. (ZMQ_CONFLATE would keep only the latest message, but it breaks multipart
// messages, so a small high-water mark does the job instead.) With several subscribers, one
// slow subscriber makes the publisher drop that set for all of them.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/stream/endpoint.h"

namespace zmq {
class context_t;
}

namespace tomorig::stream {

// Where `tomorig run --preview` and `tomorig replay --preview` publish quick-look results, and
// `tomorig preview` listens, unless told otherwise.
inline constexpr const char* kDefaultPreviewEndpoint = "tcp://127.0.0.1:5557";

// Preview defaults: tiny queues so what a viewer sees is current.
inline SocketOptions preview_socket_options(std::string address) {
  SocketOptions o;
  o.endpoint.address = std::move(address);
  o.high_water_mark = 2;
  o.timeout = std::chrono::milliseconds(1000);
  return o;
}

// A quick-look result (docs/wire-protocol.md, "Quick-look messages"): part 0 one JSON object
// (UTF-8) whose "type" says what it reports, parts 1 ... n small images as PNG files, listed in
// order by the object's "images" array.
struct PreviewMessage {
  std::string json;
  std::vector<std::string> images;  // PNG file bytes
};

struct PreviewStats {
  std::uint64_t sets_published = 0;  // messages handed to ZeroMQ (no subscriber: discarded by it)
  std::uint64_t sets_dropped = 0;    // a subscriber was full
};

class PreviewPublisher {
 public:
  PreviewPublisher(zmq::context_t& context, SocketOptions options);
  ~PreviewPublisher();
  PreviewPublisher(const PreviewPublisher&) = delete;
  PreviewPublisher& operator=(const PreviewPublisher&) = delete;

  // Publishes without waiting; false if the set was dropped because a subscriber is full.
  bool publish(const FrameSet& set);
  // The same for a quick-look result (counted in the same stats). Throws bad_input if the
  // JSON does not start with '{'.
  bool publish(const PreviewMessage& message);

  const std::string& endpoint() const;
  PreviewStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class PreviewSubscriber {
 public:
  PreviewSubscriber(zmq::context_t& context, SocketOptions options);
  ~PreviewSubscriber();
  PreviewSubscriber(const PreviewSubscriber&) = delete;
  PreviewSubscriber& operator=(const PreviewSubscriber&) = delete;

  // The next set, or nullopt after options.timeout. Malformed messages throw tomorig::Error.
  std::optional<FrameSet> receive();
  // The next quick-look result, or nullopt after options.timeout. A frame-set message, or one
  // whose first part is not a JSON object, throws tomorig::Error (bad_input) naming it.
  std::optional<PreviewMessage> receive_message();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::stream
