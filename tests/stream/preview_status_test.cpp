// The preview PUB path drops and counts when a subscriber is slow; the status PUB path
// carries JSON that round-trips exactly.
#include <gtest/gtest.h>

#include <zmq.hpp>

#include "stream_test_support.h"
#include "tomorig/stream/preview.h"
#include "tomorig/stream/status.h"

namespace tomorig::stream {
namespace {
using namespace std::chrono_literals;
using testing::expect_error;
using testing::has_pattern;
using testing::pattern_set;

constexpr std::uint64_t kProbe = 1'000'000;

// A subscription reaches the publisher asynchronously; publish probes until one arrives, so
// the real test starts with the subscriber attached and its queue empty.
void wait_until_subscribed(PreviewPublisher& pub, PreviewSubscriber& sub) {
  for (int attempt = 0; attempt < 500; ++attempt) {
    pub.publish(pattern_set(kProbe, 1, 4, 4, SampleType::u8));
    if (auto got = sub.receive()) {
      ASSERT_EQ(got->set_index, kProbe);
      return;
    }
  }
  FAIL() << "subscriber never attached";
}

TEST(Preview, SlowSubscriberCausesCountedDropsAndReceivesIntactSets) {
  zmq::context_t context;
  PreviewPublisher publisher(context, preview_socket_options("inproc://preview"));
  auto sub_options = preview_socket_options("inproc://preview");
  sub_options.endpoint.bind = false;
  sub_options.timeout = 20ms;
  PreviewSubscriber subscriber(context, sub_options);
  wait_until_subscribed(publisher, subscriber);

  const PreviewStats before = publisher.stats();
  constexpr int kSets = 50;
  int published = 0;
  for (int i = 0; i < kSets; ++i) published += publisher.publish(pattern_set(i, 2, 32, 16, SampleType::u16)) ? 1 : 0;
  const PreviewStats after = publisher.stats();
  EXPECT_EQ(after.sets_published - before.sets_published, static_cast<std::uint64_t>(published));
  EXPECT_EQ(after.sets_dropped - before.sets_dropped, static_cast<std::uint64_t>(kSets - published));
  EXPECT_GT(published, 0);
  EXPECT_LT(published, kSets) << "an idle subscriber with a 2-deep queue must cause drops";

  // Exactly the published sets are waiting, oldest first, intact.
  std::uint64_t last = 0;
  for (int i = 0; i < published; ++i) {
    auto set = subscriber.receive();
    ASSERT_TRUE(set) << "published set " << i << " missing";
    if (i > 0) {
      EXPECT_GT(set->set_index, last);
    }
    last = set->set_index;
    EXPECT_TRUE(has_pattern(set->cameras[1].b.image, set->set_index, 1, 1));
  }
  EXPECT_FALSE(subscriber.receive());
}

TEST(Preview, PublisherNeverBlocksWithoutSubscribers) {
  zmq::context_t context;
  PreviewPublisher publisher(context, preview_socket_options("tcp://127.0.0.1:*"));
  for (int i = 0; i < 20; ++i) EXPECT_TRUE(publisher.publish(pattern_set(i, 1, 8, 8, SampleType::u8)));
  EXPECT_EQ(publisher.stats().sets_dropped, 0u);
}

TEST(Preview, QuickLookMessagesArriveWholeAndFrameSetsAreNotTakenForThem) {
  zmq::context_t context;
  PreviewPublisher publisher(context, preview_socket_options("inproc://quicklook"));
  auto sub_options = preview_socket_options("inproc://quicklook");
  sub_options.endpoint.bind = false;
  sub_options.timeout = 20ms;
  PreviewSubscriber subscriber(context, sub_options);
  // Attach: probe until a message comes through.
  const PreviewMessage probe{R"({"type":"probe"})", {}};
  bool attached = false;
  for (int attempt = 0; attempt < 500 && !attached; ++attempt) {
    publisher.publish(probe);
    attached = subscriber.receive_message().has_value();
  }
  ASSERT_TRUE(attached);

  PreviewMessage message{R"({"type":"tomorig.quicklook","images":[{"name":"a"},{"name":"b"}]})",
                         {std::string("\x89PNG one", 8), std::string(5000, 'x')}};
  ASSERT_TRUE(publisher.publish(message));
  const auto got = subscriber.receive_message();
  ASSERT_TRUE(got);
  EXPECT_EQ(got->json, message.json);
  EXPECT_EQ(got->images, message.images);

  publisher.publish(pattern_set(3, 1, 4, 4, SampleType::u8));
  expect_error([&] { subscriber.receive_message(); }, ErrorKind::bad_input, {"frame-set message"});
  EXPECT_FALSE(subscriber.receive_message()) << "the rejected message is consumed";
  expect_error([&] { publisher.publish(PreviewMessage{"not json", {}}); }, ErrorKind::bad_input, {"JSON object"});
}

Status sample_status() {
  Status s;
  s.time_ns = 1'700'000'000'123'456'789;
  s.state = "running";
  s.sets_total = 12345;
  s.sets_per_second = 24.875;
  s.stream_mb_per_second = 2213.5;
  s.frames_lost = 3;
  s.incomplete_sets = 2;
  s.preview_drops = 77;
  s.queue_depth = 5;
  s.disk_mb_per_second = 1890.25;
  s.cameras = {{"cam0", 1, 1}, {"cam1", 2, 1}, {"GVA", 0, 0}};
  return s;
}

TEST(Status, JsonRoundTripIsExact) {
  const Status s = sample_status();
  EXPECT_EQ(parse_status(to_json(s)), s);
  EXPECT_EQ(parse_status(to_json(Status{})), Status{});
}

TEST(Status, JsonUsesTheDocumentedKeys) {
  const std::string json = to_json(sample_status());
  for (const char* key : {"\"type\":\"tomorig.status\"", "\"version\":1", "\"sets_per_second\"", "\"frames_lost\"",
                          "\"queue_depth\"", "\"disk_mb_per_second\"", "\"cameras\""})
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
}

TEST(Status, BadJsonIsRejectedWithAReason) {
  expect_error([] { parse_status("{not json"); }, ErrorKind::bad_input, {"not valid JSON"});
  expect_error([] { parse_status("[1,2]"); }, ErrorKind::bad_input, {"not a JSON object"});
  expect_error([] { parse_status(R"({"type":"other","version":1})"); }, ErrorKind::bad_input, {"type 'other'"});
  std::string json = to_json(sample_status());
  const auto at = json.find("\"version\":1");
  std::string v2 = json;
  v2.replace(at, 11, "\"version\":2");
  expect_error([&] { parse_status(v2); }, ErrorKind::bad_input, {"version 2", "version 1"});
  std::string missing = json;
  missing.replace(missing.find("\"queue_depth\""), 13, "\"queue_deepth\"");
  expect_error([&] { parse_status(missing); }, ErrorKind::bad_input, {"lacks key 'queue_depth'"});
  std::string mistyped = json;
  mistyped.replace(mistyped.find("\"state\":\"running\""), 17, "\"state\":5");
  expect_error([&] { parse_status(mistyped); }, ErrorKind::bad_input, {"'state' has the wrong type"});
}

TEST(Status, PublishedStatusReachesTheSubscriber) {
  zmq::context_t context;
  StatusPublisher publisher(context, status_socket_options("tcp://127.0.0.1:*"));
  auto sub_options = status_socket_options(publisher.endpoint());
  sub_options.endpoint.bind = false;
  sub_options.timeout = 20ms;
  StatusSubscriber subscriber(context, sub_options);
  Status s = sample_status();
  std::optional<Status> got;
  // Keep publishing (status is periodic anyway) until the subscription has arrived.
  for (int attempt = 0; attempt < 500 && !got; ++attempt) {
    s.sets_total = 12345 + attempt;
    publisher.publish(s);
    got = subscriber.receive();
  }
  ASSERT_TRUE(got);
  EXPECT_GE(got->sets_total, 12345u);
  got->sets_total = s.sets_total = 0;
  EXPECT_EQ(*got, s);
}

}  // namespace
}  // namespace tomorig::stream
