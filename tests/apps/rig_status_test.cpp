// The rig's status: the text line and the JSON message carry the same figures, warnings come
// before trouble (a lagging trigger, a lost camera), and the queue depth never wraps.
#include <gtest/gtest.h>

#include <string>

#include <zmq.hpp>

#include "tomorig/rig/rig_status.h"
#include "tomorig/stream/status.h"

namespace tomorig::rig {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

StatusFigures two_cameras() {
  StatusFigures f;
  f.sets = 12;
  f.total = 200;
  f.queue_depth = 1;
  f.trigger_queue_capacity = 256;
  f.trigger_rate_hz = 10.0;
  f.disk_free_bytes = 812'400'000'000;
  CameraFigures a;
  a.id = "cam0";
  a.frames = 24;
  a.underruns = 3;
  a.failed = 1;
  a.missing_packets = 17;
  a.resends = 5;
  a.mismatched = 2;
  CameraFigures b;
  b.id = "cam1";
  b.connected = false;
  b.problem = "no frame 412 ms after a trigger it took";
  b.frames = 10;
  f.cameras = {a, b};
  return f;
}

TEST(RigStatus, QueueDepthNeverWrapsWhenTheReceiverCountsASetFirst) {
  // The recorder may count a set before the sender's counter shows it: 5 sent, 6 received is
  // a moment's view of 0 sets in flight, not 18446744073709551615.
  EXPECT_EQ(sets_in_flight(5, 6), 0u);
  EXPECT_EQ(sets_in_flight(6, 5), 1u);
  EXPECT_EQ(sets_in_flight(0, 0), 0u);
}

TEST(RigStatus, TheLineAndTheJsonCarryTheSameFigures) {
  zmq::context_t context(1);
  StatusReporter reporter("recording", context, "none");
  StatusFigures f = two_cameras();
  LossTally losses({"cam0", "cam1"});
  const std::string line = reporter.line(f, losses, 331.0);
  const stream::Status s = stream::parse_status(stream::to_json(reporter.message(f, losses, 331.0)));
  EXPECT_TRUE(contains(line, "set 12/200")) << line;
  EXPECT_TRUE(contains(line, "queue 1")) << line;
  EXPECT_EQ(s.queue_depth, 1u);
  EXPECT_TRUE(contains(line, "disk: 812.4 GB free, 331 min to full")) << line;
  EXPECT_EQ(s.disk_free_bytes, 812'400'000'000);
  EXPECT_DOUBLE_EQ(s.disk_minutes_until_full, 331.0);
  EXPECT_TRUE(contains(line, "trigger: lag 0 events (0 ms) of 256, dropped 0")) << line;
  EXPECT_EQ(s.trigger_queue_capacity, 256u);
  EXPECT_TRUE(contains(line, "cam0 connected 24 frames, underruns 3, failed 1, missing packets 17, resends 5, "
                             "mismatched 2"))
      << line;
  ASSERT_EQ(s.cameras.size(), 2u);
  EXPECT_TRUE(s.cameras[0].connected);
  EXPECT_EQ(s.cameras[0].frames, 24u);
  EXPECT_EQ(s.cameras[0].underruns, 3u);
  EXPECT_EQ(s.cameras[0].failed, 1u);
  EXPECT_EQ(s.cameras[0].missing_packets, 17u);
  EXPECT_EQ(s.cameras[0].resends, 5u);
  EXPECT_EQ(s.cameras[0].mismatched, 2u);
  // The lost camera is named on the line and in the message, with the reason.
  EXPECT_TRUE(contains(line, "cam1 DISCONNECTED")) << line;
  EXPECT_TRUE(contains(line, "WARNING camera cam1 disconnected: no frame 412 ms")) << line;
  EXPECT_FALSE(s.cameras[1].connected);
  EXPECT_EQ(s.cameras[1].problem, "no frame 412 ms after a trigger it took");
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_TRUE(contains(s.warnings[0], "camera cam1 disconnected")) << s.warnings[0];
}

TEST(RigStatus, ALaggingTriggerIsWarnedAboutBeforeEventsDrop) {
  StatusFigures f = two_cameras();
  f.cameras[1].connected = true;
  f.trigger_lag_events = 63;  // under a quarter of the 256 the trigger holds: no warning yet
  EXPECT_TRUE(StatusReporter::warnings(f, -1.0).empty());
  f.trigger_lag_events = 64;
  const auto warnings = StatusReporter::warnings(f, -1.0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "lags the trigger by 64 events (6400 ms)")) << warnings[0];
  EXPECT_TRUE(contains(warnings[0], "dropped at 256")) << warnings[0];
  EXPECT_EQ(f.dropped_trigger_events, 0u);  // warned while nothing was lost yet
}

TEST(RigStatus, FreeRunningCamerasAndAFillingDiskAreWarnedAboutOnEveryLine) {
  StatusFigures f = two_cameras();
  f.cameras[1].connected = true;
  f.cameras[1].free_running = true;
  const auto warnings = StatusReporter::warnings(f, 4.5);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_TRUE(contains(warnings[0], "free-running camera cam1")) << warnings[0];
  EXPECT_TRUE(contains(warnings[0], "no set is complete")) << warnings[0];
  EXPECT_TRUE(contains(warnings[1], "full in 4.5 min")) << warnings[1];
}

}  // namespace
}  // namespace tomorig::rig
