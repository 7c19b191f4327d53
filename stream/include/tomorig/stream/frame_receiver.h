#pragma once
// The lossless path, receiving side (ZeroMQ PULL). receive() waits up to the timeout, so a
// consumer notices a sender that stopped or vanished instead of hanging. Gaps in the set
// index are counted: ZeroMQ itself never drops on this path, but sets queued towards a peer
// that crashed are gone, and the recorder must be able to say so.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "tomorig/core/frame_set.h"
#include "tomorig/stream/endpoint.h"
#include "tomorig/stream/session_messages.h"

namespace zmq {
class context_t;
}

namespace tomorig::stream {

struct ReceiverStats {
  std::uint64_t sets_received = 0;
  std::uint64_t bytes_received = 0;
  std::uint64_t sets_missing = 0;       // set indices skipped between consecutive sets
  std::uint64_t rejected_messages = 0;  // malformed messages (the decoder threw)
  std::uint64_t session_messages = 0;   // session start, set truth and session end messages
  std::uint64_t timeouts = 0;           // receive() calls that saw nothing within the timeout
};

class FrameReceiver {
 public:
  FrameReceiver(zmq::context_t& context, SocketOptions options);
  ~FrameReceiver();
  FrameReceiver(const FrameReceiver&) = delete;
  FrameReceiver& operator=(const FrameReceiver&) = delete;

  // The next set (Images are zero-copy views into the received message), or nullopt if none
  // arrived within options.timeout. A malformed message is consumed whole, counted, and
  // rethrown as tomorig::Error naming the problem; the receiver stays usable.
  // Session messages in between are skipped (counted in session_messages).
  std::optional<FrameSet> receive();
  // The next message of any kind: a frame set (as receive() returns it) or a session message
  // (tomorig/stream/session_messages.h); nullopt after options.timeout. A session start
  // restarts the count of missing set indices. Malformed messages as for receive().
  std::optional<StreamMessage> receive_message();

  const std::string& endpoint() const;
  // From the receiving thread (unlike FrameSender, the counters are not atomic).
  ReceiverStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::stream
