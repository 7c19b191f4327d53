#include "tomorig/stream/frame_sender.h"

#include <cstring>

#include <fmt/format.h>

#include "socket_setup.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {

namespace {
std::atomic<std::uint64_t> g_monitors{0};  // unique inproc names for the sockets' monitors
}  // namespace

struct FrameSender::Impl {
  detail::OpenedSocket opened;
  int receivers = 0;      // connected receivers seen on `monitor`
  std::atomic<std::uint64_t> sets_sent{0};
  std::atomic<std::uint64_t> bytes_sent{0};
  std::atomic<std::uint64_t> blocked_sends{0};
  std::atomic<std::uint64_t> timed_out_sends{0};
};

FrameSender::FrameSender(zmq::context_t& context, SocketOptions options)
    : impl_(std::make_unique<Impl>()) {
  // Closing waits up to one timeout so sets already queued still reach the receiver.
  const std::string address = fmt::format("inproc://tomorig-sender-monitor-{}", g_monitors.fetch_add(1));
  impl_->opened = detail::open_socket(context, zmq::socket_type::push, options, options.linger.value_or(options.timeout),
                                      detail::lossless_send_buffer_bytes(), address);
}

FrameSender::~FrameSender() {
  if (impl_) zmq_socket_monitor(impl_->opened.socket.handle(), nullptr, 0);
}

bool FrameSender::wait_for_receiver(std::chrono::milliseconds timeout) {
  // Each event is two parts: 6 bytes (u16 event, u32 value), then the endpoint.
  auto drain = [&] {
    zmq::message_t part;
    while (impl_->opened.monitor.recv(part, zmq::recv_flags::dontwait)) {
      std::uint16_t event = 0;
      if (part.size() >= sizeof event) std::memcpy(&event, part.data(), sizeof event);
      while (part.more() && impl_->opened.monitor.recv(part, zmq::recv_flags::dontwait)) {
      }
      if (event == ZMQ_EVENT_HANDSHAKE_SUCCEEDED) ++impl_->receivers;
      // A disconnect is also reported for a connection that never completed its handshake.
      if (event == ZMQ_EVENT_DISCONNECTED && impl_->receivers > 0) --impl_->receivers;
    }
  };
  drain();
  if (impl_->receivers > 0 || timeout.count() <= 0) return impl_->receivers > 0;
  zmq::pollitem_t item{impl_->opened.monitor.handle(), 0, ZMQ_POLLIN, 0};
  try {
    zmq::poll(&item, 1, timeout);
  } catch (const zmq::error_t& e) {
    if (e.num() != EINTR) throw;  // a signal: the caller looks at it and may wait again
  }
  drain();
  return impl_->receivers > 0;
}

bool FrameSender::send(const FrameSet& set) {
  std::vector<zmq::message_t> parts = encode_frame_set(set);
  return send_parts(parts, 1, fmt::format("set {}", set.set_index));
}

bool FrameSender::send(const SessionStart& start) {
  std::vector<zmq::message_t> parts;
  parts.push_back(encode_session_start(start));
  return send_parts(parts, 0, "the session start");
}

bool FrameSender::send(const SetTruth& truth) {
  std::vector<zmq::message_t> parts;
  parts.push_back(encode_set_truth(truth));
  return send_parts(parts, 0, fmt::format("the truth of trigger {}", truth.trigger_index));
}

bool FrameSender::send(const SessionEnd& end) {
  std::vector<zmq::message_t> parts;
  parts.push_back(encode_session_end(end));
  return send_parts(parts, 0, "the session end");
}

bool FrameSender::send_parts(std::vector<zmq::message_t>& parts, std::uint64_t frame_sets, const std::string& what) {
  std::uint64_t bytes = 0;
  for (const auto& p : parts) bytes += p.size();
  zmq::socket_t& socket = impl_->opened.socket;
  const auto flags_for = [&](std::size_t i) {
    return i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none;
  };

  // The first part decides: ZeroMQ admits or refuses a whole message at its first part, so
  // once it is in, the rest follows without waiting.
  if (!socket.send(parts[0], flags_for(0) | zmq::send_flags::dontwait)) {
    impl_->blocked_sends.fetch_add(1);
    impl_->blocked_sends.notify_all();
    if (!socket.send(parts[0], flags_for(0))) {  // waits up to the send timeout
      impl_->timed_out_sends.fetch_add(1);
      return false;
    }
  }
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (!socket.send(parts[i], flags_for(i)))
      throw runtime_error(fmt::format("{} was cut off after part {} of {} on {}; the stream is out of step", what, i,
                                      parts.size(), impl_->opened.endpoint));
  impl_->sets_sent.fetch_add(frame_sets);
  impl_->bytes_sent.fetch_add(bytes);
  return true;
}

const std::string& FrameSender::endpoint() const { return impl_->opened.endpoint; }

SenderStats FrameSender::stats() const {
  return {impl_->sets_sent.load(), impl_->bytes_sent.load(), impl_->blocked_sends.load(),
          impl_->timed_out_sends.load()};
}

void FrameSender::await_blocked_send(std::uint64_t seen) const { impl_->blocked_sends.wait(seen); }

}  // namespace tomorig::stream
