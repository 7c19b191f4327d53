#include "tomorig/stream/frame_receiver.h"

#include <cstdint>

#include "multipart.h"
#include "socket_setup.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {

struct FrameReceiver::Impl {
  detail::OpenedSocket opened;
  ReceiverStats stats;
  std::optional<std::uint64_t> last_index;
};

FrameReceiver::FrameReceiver(zmq::context_t& context, SocketOptions options)
    : impl_(std::make_unique<Impl>(
          Impl{detail::open_socket(context, zmq::socket_type::pull, options, std::chrono::milliseconds(0)), {}, {}})) {}

FrameReceiver::~FrameReceiver() = default;

std::optional<FrameSet> FrameReceiver::receive() {
  for (;;) {
    std::optional<StreamMessage> message = receive_message();
    if (!message) return std::nullopt;
    if (auto* set = std::get_if<FrameSet>(&*message)) return std::move(*set);
  }
}

std::optional<StreamMessage> FrameReceiver::receive_message() {
  auto parts = detail::receive_multipart(impl_->opened.socket);
  if (!parts) {
    ++impl_->stats.timeouts;
    return std::nullopt;
  }
  std::uint64_t bytes = 0;
  for (const auto& p : *parts) bytes += p.size();
  StreamMessage message;
  try {
    message = decode_stream_message(std::move(*parts));
  } catch (const Error&) {
    ++impl_->stats.rejected_messages;
    throw;
  }
  impl_->stats.bytes_received += bytes;
  auto* set = std::get_if<FrameSet>(&message);
  if (set == nullptr) {
    ++impl_->stats.session_messages;
    if (std::holds_alternative<SessionStart>(message)) impl_->last_index.reset();  // a new session counts from 0
    return message;
  }
  // A replay loop restarting at 0 is not a loss; only forward jumps are.
  // Saturating: a damaged but well-formed index can jump by almost 2^64.
  if (impl_->last_index && set->set_index > *impl_->last_index + 1) {
    const std::uint64_t gap = set->set_index - *impl_->last_index - 1;
    std::uint64_t& missing = impl_->stats.sets_missing;
    missing = gap > UINT64_MAX - missing ? UINT64_MAX : missing + gap;
  }
  impl_->last_index = set->set_index;
  ++impl_->stats.sets_received;
  return message;
}

const std::string& FrameReceiver::endpoint() const { return impl_->opened.endpoint; }

ReceiverStats FrameReceiver::stats() const { return impl_->stats; }

}  // namespace tomorig::stream
