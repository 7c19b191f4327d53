#include "tomorig/stream/endpoint.h"

#include <cstdlib>
#include <string>

#include <fmt/core.h>

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

std::string stream_token(const Endpoint& endpoint) {
  if (!endpoint.token.empty()) return endpoint.token;
  const char* env = std::getenv(kStreamTokenVariable);
  return env != nullptr ? std::string(env) : std::string();
}

std::string zmq_address(std::string_view address) {
  constexpr std::string_view kLocalhost = "tcp://localhost:";
  if (starts_with(address, kLocalhost)) return "tcp://127.0.0.1:" + std::string(address.substr(kLocalhost.size()));
  return std::string(address);
}

void check_address_form(std::string_view a) {
  const bool known_transport = starts_with(a, "tcp://") || starts_with(a, "ipc://") || starts_with(a, "inproc://");
  const std::size_t sep = a.find("://");
  if (!known_transport || sep + 3 >= a.size() || (starts_with(a, "tcp://") && tcp_host(a.substr(6)).empty()))
    throw bad_input("stream endpoint '" + std::string(a) +
                    "' is not a ZeroMQ address; use tcp://HOST:PORT (e.g. tcp://127.0.0.1:5555), ipc://PATH or "
                    "inproc://NAME");
}

void check_endpoint(const Endpoint& endpoint) {
  const std::string& a = endpoint.address;
  check_address_form(a);
  const bool remote = !is_local_address(a);
  if (endpoint.bind && !endpoint.allow_remote && remote)
    throw bad_input("refusing to bind stream endpoint '" + a +
                    "': it would accept connections from other hosts. Bind to loopback (e.g. tcp://127.0.0.1:" +
                    "PORT), or give " + endpoint.allow_remote_option +
                    " (with a shared token: --token or " + kStreamTokenVariable + ") to expose the stream on purpose");
  const std::string token = stream_token(endpoint);
  if (remote && token.empty())
    throw bad_input(fmt::format("stream endpoint '{}' is not on this host, so {} needs a shared token: give the same "
                                "secret to both sides with --token or the {} environment variable",
                                a, endpoint.bind ? "binding it" : "connecting to it", kStreamTokenVariable));
  if (token.size() > 255)
    throw bad_input(fmt::format("the stream token is {} bytes; use 1 to 255 bytes", token.size()));
}

}  // namespace tomorig::stream
