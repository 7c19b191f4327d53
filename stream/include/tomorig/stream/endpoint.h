#pragma once
// Where a stream socket lives, and the policy that keeps it off the network unless asked.
// Binding is allowed on loopback (tcp://127.x.x.x, localhost, [::1]), ipc:// and inproc://.
// Any other bind address (tcp://*, 0.0.0.0, a NIC's address or name) exposes the rig's
// stream to other hosts, so it needs allow_remote (--allow-remote on the command line) and a
// shared token (Endpoint::token), and prints a warning. tcp://localhost:PORT means
// tcp://127.0.0.1:PORT for bind and connect alike.
#include <chrono>
#include <optional>
#include <cstdint>
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
  // What the user sets to allow a remote bind here, named by the refusal (a command's flag,
  // a stage's key).
  std::string allow_remote_option = "--allow-remote";
  // The shared secret (1 to 255 bytes); empty: the TOMORIG_STREAM_TOKEN environment variable.
  // Required to bind beyond loopback and to connect to a non-loopback address. A socket with a
  // token uses it whatever its address (a binding side admits only peers presenting it, a
  // connecting side presents it), so both sides of a stream have the same token or none.
  std::string token;
};

// The environment variable a token is taken from when no --token is given.
inline constexpr const char* kStreamTokenVariable = "TOMORIG_STREAM_TOKEN";

// `endpoint.token`, else the environment's TOMORIG_STREAM_TOKEN, else empty.
std::string stream_token(const Endpoint& endpoint);

// The address ZeroMQ is given: tcp://localhost:PORT becomes tcp://127.0.0.1:PORT (ZeroMQ binds
// interface names, and "localhost" is none); every other address is returned as it is.
std::string zmq_address(std::string_view address);

// Connections a binding side of this process refused because their token was wrong.
struct RefusedConnections {
  std::uint64_t count = 0;
  std::string last_peer;  // the address of the last refused peer
};
RefusedConnections refused_connections();

// True for addresses that only this host can reach.
bool is_local_address(std::string_view address);

// Throws bad_input naming the accepted forms if `address` is not a ZeroMQ address.
void check_address_form(std::string_view address);

// Throws bad_input if `endpoint` is not a ZeroMQ address, binds beyond loopback without
// allow_remote (the message names endpoint.allow_remote_option), or needs a token (a bind
// beyond loopback, a connection to a non-loopback address) and has none or one over 255 bytes.
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
  // How long closing a lossless sender waits to hand its queued messages to the peer; unset:
  // `timeout`. A sender that sends in short slices (to notice Ctrl-C) still lingers long.
  std::optional<std::chrono::milliseconds> linger;
};

}  // namespace tomorig::stream
