#include "socket_setup.h"

#include <algorithm>
#include <fstream>

#include <fmt/format.h>

#include "stream_authenticator.h"
#include "tomorig/core/error.h"

namespace tomorig::stream::detail {

namespace {

// The last number of a /proc/sys file ("4096 16384 4194304" -> 4194304), or 0 if unreadable.
long last_number_in(const char* path) {
  std::ifstream in(path);
  long value = 0, last = 0;
  while (in >> value) last = value;
  return last;
}

}  // namespace

int lossless_send_buffer_bytes() {
  constexpr long kWanted = 8l << 20;
  const long cap = last_number_in("/proc/sys/net/core/wmem_max");
  const long autotune_max = last_number_in("/proc/sys/net/ipv4/tcp_wmem");
  const long asked = std::min(kWanted, cap);
  // The kernel doubles the size asked for (bookkeeping overhead).
  return asked > 0 && 2 * asked > autotune_max ? static_cast<int>(asked) : 0;
}

OpenedSocket open_socket(zmq::context_t& context, zmq::socket_type type, const SocketOptions& options,
                         std::chrono::milliseconds linger, int send_buffer_bytes, const std::string& monitor) {
  check_endpoint(options.endpoint);
  if (options.high_water_mark < 1)
    throw bad_input(fmt::format("stream high_water_mark = {} is invalid: it must be >= 1 (sets queued per socket)",
                                options.high_water_mark));
  if (options.timeout.count() < 0)
    throw bad_input(fmt::format("stream timeout = {} ms is invalid: it must be >= 0", options.timeout.count()));

  OpenedSocket opened{zmq::socket_t(context, type), {}, {}};
  zmq::socket_t& s = opened.socket;
  s.set(zmq::sockopt::sndhwm, options.high_water_mark);
  s.set(zmq::sockopt::rcvhwm, options.high_water_mark);
  s.set(zmq::sockopt::sndtimeo, static_cast<int>(options.timeout.count()));
  s.set(zmq::sockopt::rcvtimeo, static_cast<int>(options.timeout.count()));
  s.set(zmq::sockopt::linger, static_cast<int>(linger.count()));
  if (send_buffer_bytes > 0) s.set(zmq::sockopt::sndbuf, send_buffer_bytes);
  const std::string& address = options.endpoint.address;
  const std::string token = stream_token(options.endpoint);
  if (!token.empty()) {
    // ZeroMQ PLAIN: the binding side asks this process's handler to check the peer's token.
    if (options.endpoint.bind) {
      require_authenticator(context, token);
      s.set(zmq::sockopt::plain_server, 1);
      s.set(zmq::sockopt::zap_domain, "tomorig");
    } else {
      s.set(zmq::sockopt::plain_username, "tomorig");
      s.set(zmq::sockopt::plain_password, token);
    }
  }
  if (!monitor.empty() &&
      zmq_socket_monitor(s.handle(), monitor.c_str(), ZMQ_EVENT_HANDSHAKE_SUCCEEDED | ZMQ_EVENT_DISCONNECTED) != 0)
    throw runtime_error(fmt::format("cannot watch the connections of stream endpoint '{}': {}", address,
                                    zmq_strerror(zmq_errno())));
  if (!monitor.empty()) {
    // Events sent while no PAIR is connected are dropped, so connect it first.
    opened.monitor = zmq::socket_t(context, zmq::socket_type::pair);
    opened.monitor.set(zmq::sockopt::linger, 0);
    opened.monitor.connect(monitor);
  }
  const std::string target = zmq_address(address);
  if (target.find("tcp://[") == 0) s.set(zmq::sockopt::ipv6, 1);  // [::1] and other IPv6 literals
  try {
    if (options.endpoint.bind) {
      s.bind(target);
      opened.endpoint = s.get(zmq::sockopt::last_endpoint);
    } else {
      s.connect(target);
      opened.endpoint = target;
    }
  } catch (const zmq::error_t& e) {
    throw runtime_error(fmt::format("cannot {} stream endpoint '{}': {}{}", options.endpoint.bind ? "bind" : "connect",
                                    address, e.what(),
                                    e.num() == EADDRINUSE ? "; pick another port or stop the program using it" : ""));
  }
  if (options.endpoint.bind && !is_local_address(address))
    // Said by the library, so every command and stage that binds beyond loopback says it.
    fmt::print(stderr,
               "WARNING: stream endpoint {} accepts connections from other hosts. Only peers presenting the shared "
               "token are admitted, but the token and every frame cross the network unencrypted: use a network "
               "you trust.\n",
               opened.endpoint);
  return opened;
}

}  // namespace tomorig::stream::detail
