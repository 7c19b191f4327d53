#include "tomorig/stream/endpoint.h"

#include <string>

#include "tomorig/core/error.h"

namespace tomorig::stream {
namespace {

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

bool is_loopback_host(std::string_view host) {
  if (host == "localhost" || host == "[::1]" || host == "::1") return true;
  if (!starts_with(host, "127.")) return false;
  // 127.0.0.0/8 written as four decimal octets.
  int dots = 0, digits = 0;
  for (char c : host) {
    if (c == '.') {
      if (digits == 0) return false;
      ++dots;
      digits = 0;
    } else if (c >= '0' && c <= '9') {
      if (++digits > 3) return false;
    } else {
      return false;
    }
  }
  return dots == 3 && digits > 0;
}

// HOST part of tcp://HOST:PORT; empty if the address has no ":PORT".
std::string_view tcp_host(std::string_view rest) {
  const auto colon = rest.rfind(':');
  if (colon == std::string_view::npos || colon == 0 || colon + 1 == rest.size()) return {};
  return rest.substr(0, colon);
}

}  // namespace

bool is_local_address(std::string_view address) {
  if (starts_with(address, "inproc://") || starts_with(address, "ipc://")) return true;
  if (starts_with(address, "tcp://")) return is_loopback_host(tcp_host(address.substr(6)));
  return false;
}

void check_endpoint(const Endpoint& endpoint) {
  const std::string& a = endpoint.address;
  const bool known_transport = starts_with(a, "tcp://") || starts_with(a, "ipc://") || starts_with(a, "inproc://");
  const std::size_t sep = a.find("://");
  if (!known_transport || sep + 3 >= a.size() || (starts_with(a, "tcp://") && tcp_host(a.substr(6)).empty()))
    throw bad_input("stream endpoint '" + a +
                    "' is not a ZeroMQ address; use tcp://HOST:PORT (e.g. tcp://127.0.0.1:5555), ipc://PATH or "
                    "inproc://NAME");
  if (endpoint.bind && !endpoint.allow_remote && !is_local_address(a))
    throw bad_input("refusing to bind stream endpoint '" + a +
                    "': it would accept connections from other hosts. Bind to loopback (e.g. tcp://127.0.0.1:" +
                    "PORT), or set allow_remote = true for this endpoint (--allow-remote on the command line) to expose "
                    "the stream on purpose");
}

}  // namespace tomorig::stream
