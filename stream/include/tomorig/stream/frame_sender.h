#pragma once
// The lossless path, sending side (ZeroMQ PUSH). When the receiver falls behind, the queue
// fills to the high-water mark and send() waits: back-pressure reaches the producer instead of
// frames being dropped. A send that finds no room within the timeout reports it and sends
// nothing, so the caller still holds the set and decides (retry, or stop and say why).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/stream/endpoint.h"
#include "tomorig/stream/session_messages.h"

namespace zmq {
class context_t;
class message_t;
}

namespace tomorig::stream {

struct SenderStats {
  std::uint64_t sets_sent = 0;
  std::uint64_t bytes_sent = 0;       // header + pixels (and session messages)
  std::uint64_t blocked_sends = 0;    // sends that found the queue full and had to wait
  std::uint64_t timed_out_sends = 0;  // sends given up after the timeout (nothing sent)
};

class FrameSender {
 public:
  // Binds or connects at once; throws bad_input for a refused endpoint, runtime for a bind
  // failure (port in use).
  FrameSender(zmq::context_t& context, SocketOptions options);
  ~FrameSender();
  FrameSender(const FrameSender&) = delete;
  FrameSender& operator=(const FrameSender&) = delete;

  // Sends the set zero-copy; its Images stay leased until ZeroMQ has sent them. Returns false
  // if no receiver made room within options.timeout: nothing was sent.
  bool send(const FrameSet& set);
  // Session messages (start before the first set, a set's truth just before the set, end after
  // the last), with the same back-pressure and timeout. Not counted in sets_sent.
  bool send(const SessionStart& start);
  bool send(const SetTruth& truth);
  bool send(const SessionEnd& end);

  // True once a receiver has completed its connection (handshake, and token if any), waiting
  // up to `timeout` for one. A connecting PUSH socket queues messages before any receiver is
  // there, so a successful send does not tell that a receiver exists; this does. From the
  // sending thread only.
  bool wait_for_receiver(std::chrono::milliseconds timeout);

  // The address as bound (tcp://127.0.0.1:* resolved to the real port) or as connected.
  const std::string& endpoint() const;

  // Safe to call from any thread.
  SenderStats stats() const;
  // Blocks until stats().blocked_sends differs from `seen`: lets a monitor react to
  // back-pressure without polling.
  void await_blocked_send(std::uint64_t seen) const;

 private:
  bool send_parts(std::vector<zmq::message_t>& parts, std::uint64_t frame_sets, const std::string& what);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::stream
