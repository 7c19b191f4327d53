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
  // With a monitor address: a PAIR socket receiving the connection events (handshake
  // succeeded, disconnected), connected before the socket binds or connects.
  zmq::socket_t monitor;
};

// `linger`: how long closing waits to hand queued messages to the peer (lossless sockets wait,
// preview and status sockets drop). `send_buffer_bytes` > 0 sets the kernel send buffer
// (SO_SNDBUF) of the socket's TCP connections; 0 leaves the kernel's auto-tuning.
// `monitor` (an inproc:// address) receives the socket's connection events from before it
// binds or connects, so none is missed.
OpenedSocket open_socket(zmq::context_t& context, zmq::socket_type type, const SocketOptions& options,
                         std::chrono::milliseconds linger, int send_buffer_bytes = 0,
                         const std::string& monitor = {});

// The SO_SNDBUF for a lossless sender: large camera frames go out in fewer, longer writes
// when the kernel send buffer is big (measured on loopback: 20-25 % less CPU per GB with
// 8 MiB than with auto-tuning's 4 MiB). The kernel caps an explicit size at
// net.core.wmem_max (and doubles it) and stops auto-tuning, so this returns 0 (keep
// auto-tuning) when the cap would make the buffer smaller than auto-tuning's maximum
// (net.ipv4.tcp_wmem), e.g. on a stock kernel with wmem_max = 208 KiB.
int lossless_send_buffer_bytes();

}  // namespace tomorig::stream::detail
