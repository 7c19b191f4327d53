// The lossless PUSH/PULL path: back-pressure instead of loss, order kept, a vanished peer
// reported by timeouts, gaps and malformed messages counted.
#include <gtest/gtest.h>

#include <thread>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/wire_format.h"

namespace tomorig::stream {
namespace {
using namespace std::chrono_literals;
using testing::has_pattern;
using testing::pattern_set;

struct Pair {
  SocketOptions sender;
  SocketOptions receiver;
};

// Sender binds `address`; the receiver connects to what it actually bound.
Pair options_for(const std::string& address, std::chrono::milliseconds timeout) {
  Pair p;
  p.sender.endpoint.address = address;
  p.sender.high_water_mark = 2;
  p.sender.timeout = timeout;
  p.receiver = p.sender;
  p.receiver.endpoint.bind = false;
  return p;
}

class Lossless : public ::testing::TestWithParam<std::string> {};

// 200 sets through a 2-deep queue to a consumer that only starts once the producer is already
// blocked, then checks every pixel: every set arrives, in order, intact, and the producer was
// held back rather than allowed to drop.
TEST_P(Lossless, SlowConsumerGetsEverySetInOrder) {
  constexpr int kSets = 200;
  zmq::context_t context;
  auto opts = options_for(GetParam(), 10s);
  FrameSender sender(context, opts.sender);
  opts.receiver.endpoint.address = sender.endpoint();
  FrameReceiver receiver(context, opts.receiver);

  std::atomic<int> failed_sends{0};
  std::thread producer([&] {
    for (int i = 0; i < kSets; ++i)
      if (!sender.send(pattern_set(i, 2, 256, 128, SampleType::u16))) ++failed_sends;
  });
  // Start consuming only once the producer has been held back by a full queue (a block with
  // nothing sent yet may just be the connection being set up).
  std::uint64_t seen = 0;
  do {
    sender.await_blocked_send(seen);
    seen = sender.stats().blocked_sends;
  } while (sender.stats().sets_sent == 0);

  for (int i = 0; i < kSets; ++i) {
    auto set = receiver.receive();
    ASSERT_TRUE(set) << "set " << i << " never arrived";
    ASSERT_EQ(set->set_index, static_cast<std::uint64_t>(i));
    for (int c = 0; c < 2; ++c) {
      EXPECT_TRUE(has_pattern(set->cameras[c].a.image, i, c, 0)) << "set " << i << " camera " << c;
      EXPECT_TRUE(has_pattern(set->cameras[c].b.image, i, c, 1)) << "set " << i << " camera " << c;
    }
  }
  producer.join();
  EXPECT_EQ(failed_sends, 0);
  const SenderStats s = sender.stats();
  EXPECT_EQ(s.sets_sent, static_cast<std::uint64_t>(kSets));
  EXPECT_GE(s.blocked_sends, 1u);
  EXPECT_EQ(s.timed_out_sends, 0u);
  const ReceiverStats r = receiver.stats();
  EXPECT_EQ(r.sets_received, static_cast<std::uint64_t>(kSets));
  EXPECT_EQ(r.sets_missing, 0u);
  EXPECT_EQ(r.bytes_received, s.bytes_sent);
}

INSTANTIATE_TEST_SUITE_P(Transports, Lossless, ::testing::Values("inproc://lossless", "tcp://127.0.0.1:*"),
                         [](const auto& info) { return info.param.substr(0, info.param.find(':')); });

TEST(LosslessPeers, ReceiverWithoutSenderTimesOut) {
  zmq::context_t context;
  auto opts = options_for("tcp://127.0.0.1:*", 50ms);
  opts.receiver.endpoint.bind = true;
  FrameReceiver receiver(context, opts.receiver);
  EXPECT_FALSE(receiver.receive());
  EXPECT_EQ(receiver.stats().timeouts, 1u);
}

TEST(LosslessPeers, SenderWithoutReceiverGivesUpAndKeepsTheSet) {
  zmq::context_t context;
  auto opts = options_for("tcp://127.0.0.1:*", 50ms);
  FrameSender sender(context, opts.sender);
  EXPECT_FALSE(sender.send(pattern_set(0, 1, 8, 8, SampleType::u8)));
  EXPECT_EQ(sender.stats().timed_out_sends, 1u);
  EXPECT_EQ(sender.stats().sets_sent, 0u);
}

TEST(LosslessPeers, SenderThatVanishesIsNoticedByTheReceiver) {
  zmq::context_t context;
  auto opts = options_for("tcp://127.0.0.1:*", 5s);
  opts.receiver.endpoint.bind = true;
  opts.receiver.timeout = 200ms;
  FrameReceiver receiver(context, opts.receiver);
  {
    opts.sender.endpoint = {receiver.endpoint(), false, false};
    FrameSender sender(context, opts.sender);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(sender.send(pattern_set(i, 1, 16, 16, SampleType::u16)));
  }  // sender closes; lingers until its queue is delivered
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(receiver.receive()) << "set " << i;
  EXPECT_FALSE(receiver.receive()) << "no sender left, receive() must time out";
}

TEST(LosslessPeers, GapsInTheSetIndexAreCounted) {
  zmq::context_t context;
  auto opts = options_for("inproc://gaps", 1s);
  FrameSender sender(context, opts.sender);
  FrameReceiver receiver(context, opts.receiver);
  for (std::uint64_t index : {0u, 1u, 4u, 5u}) {
    ASSERT_TRUE(sender.send(pattern_set(index, 1, 4, 4, SampleType::u8)));
    ASSERT_TRUE(receiver.receive());
  }
  EXPECT_EQ(receiver.stats().sets_missing, 2u);
}

TEST(LosslessPeers, MalformedMessageIsRejectedAndTheStreamContinues) {
  zmq::context_t context;
  auto opts = options_for("inproc://malformed", 1s);
  opts.receiver.endpoint.bind = true;
  FrameReceiver receiver(context, opts.receiver);
  zmq::socket_t rogue(context, zmq::socket_type::push);
  rogue.connect("inproc://malformed");
  rogue.send(zmq::str_buffer("hello"), zmq::send_flags::sndmore);
  rogue.send(zmq::str_buffer("world"), zmq::send_flags::none);
  auto parts = encode_frame_set(pattern_set(9, 1, 4, 4, SampleType::u16));
  for (std::size_t i = 0; i < parts.size(); ++i)
    rogue.send(parts[i], i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);

  testing::expect_error([&] { receiver.receive(); }, ErrorKind::bad_input, {"magic"});
  const auto good = receiver.receive();
  ASSERT_TRUE(good);
  EXPECT_EQ(good->set_index, 9u);
  EXPECT_EQ(receiver.stats().rejected_messages, 1u);
}

TEST(LosslessPeers, PeerOnAnOldProtocolVersionIsRefusedNamingBothVersions) {
  zmq::context_t context;
  auto opts = options_for("inproc://old-peer", 1s);
  opts.receiver.endpoint.bind = true;
  FrameReceiver receiver(context, opts.receiver);
  zmq::socket_t old_peer(context, zmq::socket_type::push);
  old_peer.connect("inproc://old-peer");
  auto parts = encode_frame_set(pattern_set(1, 1, 4, 4, SampleType::u16));
  static_cast<std::uint8_t*>(parts[0].data())[4] = 0;  // version field, low byte
  for (std::size_t i = 0; i < parts.size(); ++i)
    old_peer.send(parts[i], i + 1 < parts.size() ? zmq::send_flags::sndmore : zmq::send_flags::none);
  testing::expect_error([&] { receiver.receive(); }, ErrorKind::bad_input,
                        {"protocol version 0", "speaks version " + std::to_string(kWireProtocolVersion)});
}

}  // namespace
}  // namespace tomorig::stream
