#include "stream_authenticator.h"

#include <atomic>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/core.h>

#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"
#include "tomorig/stream/endpoint.h"

namespace tomorig::stream {
namespace {

std::mutex g_mutex;                            // guards the two maps below and g_last_peer
std::map<void*, std::string> g_tokens;         // contexts with a running handler, by their token
std::atomic<std::uint64_t> g_refused{0};
std::string g_last_peer;
// Refusals are printed only this often: a peer retrying with a wrong token (ZeroMQ reconnects
// every 100 ms) must not flood the terminal.
constexpr std::uint64_t kPrintedRefusals = 10;

// Constant-time comparison: the time a refusal takes says nothing about the token.
bool same_token(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i)
    diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

void serve(zmq::socket_t socket, void* key, std::string token) {
  for (;;) {
    std::vector<zmq::message_t> request;
    try {
      zmq::message_t part;
      do {
        if (!socket.recv(part)) continue;
        request.push_back(std::move(part));
        part = zmq::message_t();
      } while (socket.get(zmq::sockopt::rcvmore));
    } catch (const zmq::error_t& e) {
      if (e.num() == EINTR) continue;
      break;  // ETERM: the context is closing
    }
    // version, request id, domain, address, identity, mechanism, then the PLAIN credentials.
    auto text = [&](std::size_t i) { return i < request.size() ? request[i].to_string() : std::string(); };
    const bool admitted = request.size() == 8 && text(5) == "PLAIN" && same_token(text(7), token);
    if (!admitted) {
      const std::uint64_t n = ++g_refused;
      const std::string peer = printable(text(3));
      {
        const std::lock_guard lock(g_mutex);
        g_last_peer = peer;
      }
      if (n <= kPrintedRefusals)
        fmt::print(stderr, "stream: refused a connection from {}: {} ({} refused so far)\n", peer,
                   text(5) == "PLAIN" ? "wrong token" : "no token", n);
    }
    try {
      std::vector<zmq::message_t> reply;
      reply.emplace_back(std::string("1.0"));
      reply.emplace_back(request.size() > 1 ? request[1].to_string() : std::string());
      reply.emplace_back(std::string(admitted ? "200" : "400"));
      reply.emplace_back(std::string(admitted ? "OK" : "wrong token"));
      reply.emplace_back(std::string(admitted ? "tomorig" : ""));
      reply.emplace_back();
      for (std::size_t i = 0; i < reply.size(); ++i)
        socket.send(reply[i], i + 1 < reply.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
    } catch (const zmq::error_t&) {
      break;
    }
  }
  {
    const std::lock_guard lock(g_mutex);
    g_tokens.erase(key);  // before the socket closes: only then can the context's memory be reused
  }
  socket.close();
}

}  // namespace

RefusedConnections refused_connections() {
  const std::lock_guard lock(g_mutex);
  return {g_refused.load(), g_last_peer};
}

namespace detail {

void require_authenticator(zmq::context_t& context, const std::string& token) {
  const std::lock_guard lock(g_mutex);
  void* key = context.handle();
  if (const auto it = g_tokens.find(key); it != g_tokens.end()) {
    if (!same_token(it->second, token))
      throw bad_input("two stream sockets of one process have different tokens; give every socket the same --token");
    return;
  }
  zmq::socket_t socket(context, zmq::socket_type::rep);
  socket.set(zmq::sockopt::linger, 0);
  socket.bind("inproc://zeromq.zap.01");  // the address libzmq sends its authentication requests to
  g_tokens.emplace(key, token);
  std::thread(serve, std::move(socket), key, token).detach();
}

}  // namespace detail
}  // namespace tomorig::stream
