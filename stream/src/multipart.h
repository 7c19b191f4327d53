#pragma once
// Receives one whole multipart message, waiting at most the socket's receive timeout.
#include <optional>
#include <vector>

#include <zmq.hpp>

namespace tomorig::stream::detail {

// nullopt if nothing arrived in time; `wait` = false polls once without waiting.
inline std::optional<std::vector<zmq::message_t>> receive_multipart(zmq::socket_t& socket, bool wait = true) {
  std::vector<zmq::message_t> parts(1);
  if (!socket.recv(parts[0], wait ? zmq::recv_flags::none : zmq::recv_flags::dontwait)) return std::nullopt;
  // The remaining parts of a message are already here: ZeroMQ delivers messages whole.
  while (parts.back().more()) {
    parts.emplace_back();
    (void)socket.recv(parts.back(), zmq::recv_flags::none);
  }
  return parts;
}

}  // namespace tomorig::stream::detail
