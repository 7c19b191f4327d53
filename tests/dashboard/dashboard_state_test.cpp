// The dashboard's shared state: quick-look messages checked as they arrive, latest-wins events
// (a slow page skips updates, never queues them), and close() waking every waiting stream.
#include <gtest/gtest.h>

#include <thread>

#include <nlohmann/json.hpp>

#include "dashboard_messages.h"
#include "tomorig/core/error.h"
#include "tomorig/dashboard/dashboard_state.h"

namespace tomorig::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

void expect_refused(dashboard::DashboardState& state, const stream::PreviewMessage& m, const std::string& words) {
  try {
    state.take_message(m);
    ADD_FAILURE() << "accepted " << m.json.substr(0, 80);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(DashboardState, RefusesWhatIsNotAQuickLookMessage) {
  dashboard::DashboardState state;
  expect_refused(state, {"[1,2]", {}}, "not an object");
  expect_refused(state, {R"({"type":"tomorig.status","version":1})", {}}, "type 'tomorig.status'");
  stream::PreviewMessage newer = testing::quicklook_message(1);
  newer.json.replace(newer.json.find("\"version\":1"), 11, "\"version\":2");
  expect_refused(state, newer, "version 2");
  stream::PreviewMessage short_of_parts = testing::quicklook_message(1);
  short_of_parts.images.pop_back();
  expect_refused(state, short_of_parts, "1 image parts");
  stream::PreviewMessage not_png = testing::quicklook_message(1);
  not_png.images[0] = "GIF89a";
  expect_refused(state, not_png, "not a PNG");
  EXPECT_EQ(state.messages(), 0u);
  EXPECT_FALSE(state.image("cam0/a")) << "nothing of a refused message is kept";
  EXPECT_THROW(state.take_status("{\"type\":\"tomorig.status\"}"), Error);
}

TEST(DashboardState, ASlowReaderGetsTheNewestValueOnly) {
  dashboard::DashboardState state;
  dashboard::EventCursor cursor;
  auto first = state.wait_events(cursor, 0ms);
  ASSERT_EQ(first.size(), 1u) << "the (empty) alarm list";
  EXPECT_EQ(first[0].name, "alarms");
  for (std::uint64_t set = 1; set <= 5; ++set) state.take_message(testing::quicklook_message(set, 0.01 * set));
  const auto events = state.wait_events(cursor, 0ms);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].name, "quicklook");
  EXPECT_EQ(json::parse(events[0].data).at("set"), 5);
  EXPECT_TRUE(state.wait_events(cursor, 0ms).empty()) << "nothing new";
  EXPECT_EQ(state.messages(), 5u);
}

TEST(DashboardState, ANewMessageWakesAWaitingStreamAndCloseEndsIt) {
  dashboard::DashboardState state;
  dashboard::EventCursor cursor;
  state.wait_events(cursor, 0ms);
  std::vector<dashboard::DashboardEvent> got;
  std::thread reader([&] { got = state.wait_events(cursor, 60s); });
  state.take_message(testing::preview_message(9));
  reader.join();  // returns because of the message, long before 60 s
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].name, "preview");

  std::thread waiting([&] { got = state.wait_events(cursor, 60s); });
  state.close();
  waiting.join();
  EXPECT_TRUE(got.empty());
  EXPECT_TRUE(state.closed());
}

}  // namespace
}  // namespace tomorig::testing
