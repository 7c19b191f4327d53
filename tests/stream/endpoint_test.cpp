// Stream endpoints stay on this host unless remote access is asked for explicitly.
#include <gtest/gtest.h>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/preview.h"

namespace tomorig::stream {
namespace {
using testing::expect_error;

TEST(Endpoint, DefaultIsLoopback) {
  const Endpoint e;
  EXPECT_TRUE(e.bind);
  EXPECT_FALSE(e.allow_remote);
  EXPECT_TRUE(is_local_address(e.address));
  EXPECT_NO_THROW(check_endpoint(e));
}

TEST(Endpoint, LocalAddressesMayBeBound) {
  for (const char* a : {"tcp://127.0.0.1:5555", "tcp://127.0.0.2:*", "tcp://localhost:1", "tcp://[::1]:9",
                        "ipc:///tmp/tomorig.sock", "inproc://frames"}) {
    EXPECT_TRUE(is_local_address(a)) << a;
    EXPECT_NO_THROW(check_endpoint({a, true, false})) << a;
  }
}

TEST(Endpoint, NetworkAddressesNeedAllowRemote) {
  for (const char* a : {"tcp://*:5555", "tcp://0.0.0.0:5555", "tcp://192.168.1.20:5555", "tcp://eth0:5555",
                        "tcp://[::]:5555", "tcp://127.0.0.1.example.org:5555", "tcp://127.0.0:5555"}) {
    EXPECT_FALSE(is_local_address(a)) << a;
    expect_error([&] { check_endpoint({a, true, false}); }, ErrorKind::bad_input,
                 {"refusing to bind", a, "allow_remote = true"});
    EXPECT_NO_THROW(check_endpoint({a, true, true})) << a;
    EXPECT_NO_THROW(check_endpoint({a, false, false})) << "connecting is not restricted: " << a;
  }
}

TEST(Endpoint, MalformedAddressesAreRejected) {
  for (const char* a : {"", "127.0.0.1:5555", "tcp://127.0.0.1", "tcp://:5555", "udp://127.0.0.1:5", "inproc://"})
    expect_error([&] { check_endpoint({a, true, false}); }, ErrorKind::bad_input, {"not a ZeroMQ address"});
}

TEST(Endpoint, SocketsApplyThePolicyBeforeBinding) {
  zmq::context_t context;
  SocketOptions o;
  o.endpoint.address = "tcp://*:0";
  expect_error([&] { FrameSender sender(context, o); }, ErrorKind::bad_input, {"allow_remote"});
  expect_error([&] { PreviewPublisher pub(context, o); }, ErrorKind::bad_input, {"allow_remote"});
  o.endpoint.address = "tcp://127.0.0.1:*";
  o.high_water_mark = 0;
  expect_error([&] { FrameSender sender(context, o); }, ErrorKind::bad_input, {"high_water_mark = 0"});
}

TEST(Endpoint, PortInUseIsARuntimeErrorNamingTheAddress) {
  zmq::context_t context;
  SocketOptions o;
  o.endpoint.address = "tcp://127.0.0.1:*";
  FrameSender first(context, o);
  o.endpoint.address = first.endpoint();
  expect_error([&] { FrameSender second(context, o); }, ErrorKind::runtime, {"cannot bind", first.endpoint()});
}

}  // namespace
}  // namespace tomorig::stream
