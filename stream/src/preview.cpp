#include "tomorig/stream/preview.h"

#include <algorithm>

#include <fmt/format.h>

#include "multipart.h"
#include "socket_setup.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {

struct PreviewPublisher::Impl {
  detail::OpenedSocket opened;
  PreviewStats stats;
};

PreviewPublisher::PreviewPublisher(zmq::context_t& context, SocketOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->opened = detail::open_socket(context, zmq::socket_type::pub, options, std::chrono::milliseconds(0));
  // Without this a PUB socket discards silently for a full subscriber; with it the send
  // fails with EAGAIN, which is how drops get counted.
  impl_->opened.socket.set(zmq::sockopt::xpub_nodrop, 1);
}

PreviewPublisher::~PreviewPublisher() = default;

bool PreviewPublisher::publish(const FrameSet& set) {
  std::vector<zmq::message_t> parts = encode_frame_set(set);
  zmq::socket_t& socket = impl_->opened.socket;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const auto flags = (i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none) |
                       zmq::send_flags::dontwait;
    if (!socket.send(parts[i], flags)) {
      if (i == 0) {
        ++impl_->stats.sets_dropped;
        return false;
      }
      throw runtime_error(fmt::format("preview set {} was cut off after part {} of {}", set.set_index, i,
                                      parts.size()));
    }
  }
  ++impl_->stats.sets_published;
  return true;
}

bool PreviewPublisher::publish(const PreviewMessage& message) {
  if (message.json.empty() || message.json.front() != '{')
    throw bad_input("a quick-look message must start with a JSON object");
  zmq::socket_t& socket = impl_->opened.socket;
  const std::size_t parts = 1 + message.images.size();
  for (std::size_t i = 0; i < parts; ++i) {
    const std::string& bytes = i == 0 ? message.json : message.images[i - 1];
    const auto flags = (i + 1 < parts ? zmq::send_flags::sndmore : zmq::send_flags::none) | zmq::send_flags::dontwait;
    if (!socket.send(zmq::buffer(bytes), flags)) {
      if (i == 0) {
        ++impl_->stats.sets_dropped;
        return false;
      }
      throw runtime_error(fmt::format("quick-look message was cut off after part {} of {}", i, parts));
    }
  }
  ++impl_->stats.sets_published;
  return true;
}

const std::string& PreviewPublisher::endpoint() const { return impl_->opened.endpoint; }
PreviewStats PreviewPublisher::stats() const { return impl_->stats; }

struct PreviewSubscriber::Impl {
  detail::OpenedSocket opened;
};

PreviewSubscriber::PreviewSubscriber(zmq::context_t& context, SocketOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->opened = detail::open_socket(context, zmq::socket_type::sub, options, std::chrono::milliseconds(0));
  impl_->opened.socket.set(zmq::sockopt::subscribe, "");
}

PreviewSubscriber::~PreviewSubscriber() = default;

std::optional<FrameSet> PreviewSubscriber::receive() {
  auto parts = detail::receive_multipart(impl_->opened.socket);
  if (!parts) return std::nullopt;
  return decode_frame_set(std::move(*parts));
}

std::optional<PreviewMessage> PreviewSubscriber::receive_message() {
  auto parts = detail::receive_multipart(impl_->opened.socket);
  if (!parts) return std::nullopt;
  const zmq::message_t& head = (*parts)[0];
  const auto* bytes = static_cast<const char*>(head.data());
  if (head.size() >= 4 && std::equal(bytes, bytes + 4, reinterpret_cast<const char*>(kWireMagic)))
    throw bad_input("a frame-set message arrived on the preview stream where quick-look results were expected; "
                    "connect to the quick-look endpoint (tomorig run --preview), not to a frame stream");
  if (head.size() == 0 || bytes[0] != '{')
    throw bad_input(fmt::format("a preview message of {} parts does not start with a JSON object, so it is not a "
                                "tomorig quick-look message",
                                parts->size()));
  PreviewMessage message;
  message.json.assign(bytes, head.size());
  for (std::size_t i = 1; i < parts->size(); ++i)
    message.images.emplace_back(static_cast<const char*>((*parts)[i].data()), (*parts)[i].size());
  return message;
}

}  // namespace tomorig::stream
