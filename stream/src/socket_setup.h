#pragma once
// Creates a configured ZeroMQ socket for one stream endpoint: policy check, high-water marks,
// timeouts, then bind or connect with an error that names the address.
#include <chrono>
#include <string>

#include <zmq.hpp>

#include "tomorig/stream/endpoint.h"

namespace tomorig::stream::detail {

struct OpenedSocket {
  zmq::socket_t socket;
  std::string endpoint;  // as bound (a "*" port resolved to the real one) or as connected
};

// `linger`: how long closing waits to hand queued messages to the peer (lossless sockets wait,
// preview and status sockets drop).
OpenedSocket open_socket(zmq::context_t& context, zmq::socket_type type, const SocketOptions& options,
                         std::chrono::milliseconds linger);

}  // namespace tomorig::stream::detail
