#include "socket_setup.h"

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::stream::detail {

OpenedSocket open_socket(zmq::context_t& context, zmq::socket_type type, const SocketOptions& options,
                         std::chrono::milliseconds linger) {
  check_endpoint(options.endpoint);
  if (options.high_water_mark < 1)
    throw bad_input(fmt::format("stream high_water_mark = {} is invalid: it must be >= 1 (sets queued per socket)",
                                options.high_water_mark));
  if (options.timeout.count() < 0)
    throw bad_input(fmt::format("stream timeout = {} ms is invalid: it must be >= 0", options.timeout.count()));

  OpenedSocket opened{zmq::socket_t(context, type), {}};
  zmq::socket_t& s = opened.socket;
  s.set(zmq::sockopt::sndhwm, options.high_water_mark);
  s.set(zmq::sockopt::rcvhwm, options.high_water_mark);
  s.set(zmq::sockopt::sndtimeo, static_cast<int>(options.timeout.count()));
  s.set(zmq::sockopt::rcvtimeo, static_cast<int>(options.timeout.count()));
  s.set(zmq::sockopt::linger, static_cast<int>(linger.count()));
  const std::string& address = options.endpoint.address;
  try {
    if (options.endpoint.bind) {
      s.bind(address);
      opened.endpoint = s.get(zmq::sockopt::last_endpoint);
    } else {
      s.connect(address);
      opened.endpoint = address;
    }
  } catch (const zmq::error_t& e) {
    throw runtime_error(fmt::format("cannot {} stream endpoint '{}': {}{}", options.endpoint.bind ? "bind" : "connect",
                                    address, e.what(),
                                    e.num() == EADDRINUSE ? "; pick another port or stop the program using it" : ""));
  }
  return opened;
}

}  // namespace tomorig::stream::detail
