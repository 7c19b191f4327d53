#pragma once
// The ZeroMQ authentication handler (ZAP, RFC 27) of one context: a thread that answers the
// PLAIN handshakes of every binding socket of the context that has a token, admitting a peer
// only if its password is the token. Refused peers are counted process-wide and named on
// stderr (refused_connections() in tomorig/stream/endpoint.h).
#include <string>

#include <zmq.hpp>

namespace tomorig::stream::detail {

// Starts the handler of `context` with `token` if it has none yet; throws bad_input if it has
// one with another token (all sockets of a context share one handler). The handler ends by
// itself when the context is closed.
void require_authenticator(zmq::context_t& context, const std::string& token);

}  // namespace tomorig::stream::detail
