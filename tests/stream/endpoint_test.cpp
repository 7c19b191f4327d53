// Stream endpoints stay on this host unless remote access is asked for explicitly.
#include <gtest/gtest.h>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/frame_receiver.h"
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
                 {"refusing to bind", a, "--allow-remote", "--token"});
    // Beyond loopback both sides need the shared token, binding and connecting alike.
    expect_error([&] { check_endpoint({a, true, true}); }, ErrorKind::bad_input,
                 {a, "needs a shared token", "--token", "TOMORIG_STREAM_TOKEN"});
    expect_error([&] { check_endpoint({a, false, false}); }, ErrorKind::bad_input, {"needs a shared token"});
    EXPECT_NO_THROW(check_endpoint({a, true, true, "--allow-remote", "s3cret"})) << a;
    EXPECT_NO_THROW(check_endpoint({a, false, false, "--allow-remote", "s3cret"})) << a;
  }
}

TEST(Endpoint, TheRefusalNamesTheOptionTheCallerHas) {
  Endpoint e{"tcp://0.0.0.0:5555", true, false, "the stage key allow_remote=true"};
  expect_error([&] { check_endpoint(e); }, ErrorKind::bad_input, {"the stage key allow_remote=true"});
  e.token = std::string(256, 'x');
  e.allow_remote = true;
  expect_error([&] { check_endpoint(e); }, ErrorKind::bad_input, {"256 bytes", "1 to 255"});
}

// ZeroMQ binds interface names, and "localhost" is none: it used to pass the loopback check and
// then fail to bind with "No such device".
TEST(Endpoint, LocalhostMeansLoopbackForBindAndConnect) {
  EXPECT_EQ(zmq_address("tcp://localhost:5555"), "tcp://127.0.0.1:5555");
  EXPECT_EQ(zmq_address("tcp://127.0.0.2:1"), "tcp://127.0.0.2:1");
  zmq::context_t context;
  SocketOptions o;
  o.endpoint.address = "tcp://localhost:*";
  o.timeout = std::chrono::seconds(10);
  FrameSender sender(context, o);
  ASSERT_EQ(sender.endpoint().rfind("tcp://127.0.0.1:", 0), 0u) << sender.endpoint();
  SocketOptions r = o;
  r.endpoint = {"tcp://localhost:" + sender.endpoint().substr(sender.endpoint().rfind(':') + 1), false};
  FrameReceiver receiver(context, r);
  ASSERT_TRUE(sender.send(testing::pattern_set(3, 1, 4, 4, SampleType::u8)));
  const auto got = receiver.receive();
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->set_index, 3u);
}

// A sender bound beyond loopback admits only receivers presenting its token; the others are
// refused, counted and named, and never receive a set.
TEST(Endpoint, RemoteBindAdmitsOnlyPeersWithTheToken) {
  zmq::context_t sender_context;
  SocketOptions o;
  o.endpoint = {"tcp://0.0.0.0:*", true, true, "--allow-remote", "s3cret"};
  o.timeout = std::chrono::milliseconds(300);
  FrameSender sender(sender_context, o);
  const std::string port = sender.endpoint().substr(sender.endpoint().rfind(':') + 1);
  const std::uint64_t refused_before = refused_connections().count;

  zmq::context_t wrong_context;
  SocketOptions r;
  r.endpoint = {"tcp://127.0.0.1:" + port, false, false, "--allow-remote", "guess"};
  r.timeout = std::chrono::milliseconds(100);
  {
    FrameReceiver wrong(wrong_context, r);
    // The handshake runs in ZeroMQ's threads: wait (bounded) until the refusal is counted.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
    while (refused_connections().count == refused_before && std::chrono::steady_clock::now() < deadline)
      EXPECT_FALSE(wrong.receive().has_value());
    // No receiver was admitted, so the sender finds no peer to queue for.
    EXPECT_FALSE(sender.send(testing::pattern_set(1, 1, 4, 4, SampleType::u8)));
    EXPECT_FALSE(wrong.receive().has_value());
  }
  EXPECT_GT(refused_connections().count, refused_before);
  EXPECT_EQ(refused_connections().last_peer, "127.0.0.1");

  zmq::context_t right_context;
  r.endpoint.token = "s3cret";
  r.timeout = std::chrono::seconds(10);
  FrameReceiver right(right_context, r);
  // The admitted receiver connects asynchronously: retry the 300 ms send (bounded).
  bool sent = false;
  for (int attempt = 0; attempt < 60 && !sent; ++attempt) sent = sender.send(testing::pattern_set(2, 1, 4, 4, SampleType::u8));
  ASSERT_TRUE(sent);
  const auto got = right.receive();
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->set_index, 2u);
}

TEST(Endpoint, MalformedAddressesAreRejected) {
  for (const char* a : {"", "127.0.0.1:5555", "tcp://127.0.0.1", "tcp://:5555", "udp://127.0.0.1:5", "inproc://"})
    expect_error([&] { check_endpoint({a, true, false}); }, ErrorKind::bad_input, {"not a ZeroMQ address"});
}

TEST(Endpoint, SocketsApplyThePolicyBeforeBinding) {
  zmq::context_t context;
  SocketOptions o;
  o.endpoint.address = "tcp://*:0";
  expect_error([&] { FrameSender sender(context, o); }, ErrorKind::bad_input, {"--allow-remote"});
  expect_error([&] { PreviewPublisher pub(context, o); }, ErrorKind::bad_input, {"--allow-remote"});
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
