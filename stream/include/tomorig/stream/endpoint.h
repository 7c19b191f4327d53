#pragma once
// Where a stream socket lives, and the policy that keeps it off the network unless asked.
// Binding is allowed on loopback (tcp://127.x.x.x, localhost, [::1]), ipc:// and inproc://.
// Any other bind address (tcp://*, 0.0.0.0, a NIC's address or name) exposes the rig's
// stream to other hosts, so it needs allow_remote = true. Connecting has no restriction.
#include <chrono>
#include <string>
#include <string_view>

namespace tomorig::stream {

struct Endpoint {
  // A ZeroMQ address: tcp://HOST:PORT (PORT may be * for "any free port"), ipc://PATH,
  // inproc://NAME (same process and context).
  std::string address = "tcp://127.0.0.1:5555";
  // true: this side binds (waits for peers); false: it connects to a peer that binds.
  bool bind = true;
  // Bind to a non-loopback address on purpose (e.g. a recorder on another host).
  bool allow_remote = false;
};

// True for addresses that only this host can reach.
bool is_local_address(std::string_view address);

// Throws bad_input if `endpoint` is not a ZeroMQ address, or binds beyond loopback without
// allow_remote; the message says how to allow it.
void check_endpoint(const Endpoint& endpoint);

// Options shared by the stream sockets.
struct SocketOptions {
  Endpoint endpoint;
  // Messages (whole sets) this socket queues. Lossless sockets block when full; preview and
  // status sockets drop instead. Each queued set pins its camera buffers, so keep it small.
  int high_water_mark = 4;
  // How long send() waits for room, or receive() for a message, before reporting that the
  // peer is gone or stalled (never hangs forever).
  std::chrono::milliseconds timeout{2000};
};

}  // namespace tomorig::stream
