#include "multipart.h"
#include "socket_setup.h"
#include "tomorig/stream/status.h"

namespace tomorig::stream {

struct StatusPublisher::Impl {
  detail::OpenedSocket opened;
};

StatusPublisher::StatusPublisher(zmq::context_t& context, SocketOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->opened = detail::open_socket(context, zmq::socket_type::pub, options, std::chrono::milliseconds(0));
  impl_->opened.socket.set(zmq::sockopt::xpub_nodrop, 1);  // report a full subscriber instead of hiding it
}

StatusPublisher::~StatusPublisher() = default;

bool StatusPublisher::publish(const Status& status) {
  const std::string text = to_json(status);
  return impl_->opened.socket.send(zmq::buffer(text), zmq::send_flags::dontwait).has_value();
}

const std::string& StatusPublisher::endpoint() const { return impl_->opened.endpoint; }

struct StatusSubscriber::Impl {
  detail::OpenedSocket opened;
};

StatusSubscriber::StatusSubscriber(zmq::context_t& context, SocketOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->opened = detail::open_socket(context, zmq::socket_type::sub, options, std::chrono::milliseconds(0));
  impl_->opened.socket.set(zmq::sockopt::subscribe, "");
}

StatusSubscriber::~StatusSubscriber() = default;

std::optional<Status> StatusSubscriber::receive() {
  auto parts = detail::receive_multipart(impl_->opened.socket);
  if (!parts) return std::nullopt;
  return parse_status(parts->front().to_string_view());
}

}  // namespace tomorig::stream
