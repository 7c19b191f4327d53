// rig::StreamRecording fed by rig::SessionReplay: replay -> record copies a session, checked
// against the original file (sets, pixels, rig config, truth), and bad options are refused
// before any socket or file exists.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <future>
#include <string>
#include <thread>

#include "temp_dir.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/rig_runner.h"
#include "tomorig/rig/session_replay.h"
#include "tomorig/rig/stream_recording.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

std::filesystem::path record_rig(const TempDir& tmp, std::uint64_t sets) {
  rig::RigRunOptions options;
  options.acquisition.sets = sets;
  options.acquisition.pacing = trigger::Pacing::as_fast_as_consumed;
  options.recorder.out = tmp / "original.h5";
  options.status_endpoint = "none";
  rig::RigRunner(config::default_rig_config(), options).run();
  return tmp / "original.h5";
}

TEST(StreamRecording, ReplayThenRecordCopiesTheSession) {
  TempDir tmp;
  const std::filesystem::path original = record_rig(tmp, 3);
  rig::StreamRecordingOptions options;
  options.from = "tcp://127.0.0.1:*";
  options.bind = true;
  options.idle_timeout_s = 20;  // a safety net: the replay's session end ends the recording
  options.recorder.out = tmp / "copy.h5";
  rig::StreamRecording recording(options);

  std::promise<std::string> bound;
  std::vector<std::string> notices;
  rig::StreamRecordingReport report;
  std::string error;
  std::thread recorder([&] {
    try {
      report = recording.run({.receiving = [&](const std::string& endpoint) { bound.set_value(endpoint); },
                              .notice = [&](const std::string& text) { notices.push_back(text); }});
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  rig::SessionReplayOptions replay;
  replay.session = original;
  replay.to = bound.get_future().get();
  replay.connect = true;
  replay.rate = "max";
  const rig::SessionReplayReport sent = rig::SessionReplay(replay).run();
  recorder.join();
  ASSERT_TRUE(error.empty()) << error;

  EXPECT_EQ(sent.sets_sent, 3u);
  EXPECT_EQ(report.recording.written, 3u);
  EXPECT_EQ(report.received_sets, 3u);
  EXPECT_EQ(report.rejected, 0u);
  EXPECT_EQ(report.received.sets_missing, 0u);
  ASSERT_TRUE(report.sender_end.has_value());
  EXPECT_EQ(report.sender_end->outcome, stream::SessionOutcome::completed);
  EXPECT_TRUE(report.failure().empty()) << report.failure();
  EXPECT_TRUE(report.stopped_by.empty());
  EXPECT_NE(report.brief().find("0 lost sets, 0 refused sets"), std::string::npos) << report.brief();
  ASSERT_FALSE(notices.empty());
  EXPECT_EQ(notices[0].rfind("session ", 0), 0u) << notices[0];

  const storage::SessionReader a(original), b(tmp / "copy.h5");
  EXPECT_TRUE(b.recording_complete());
  ASSERT_EQ(b.set_count(), a.set_count());
  EXPECT_EQ(b.info().rig_config_toml, a.info().rig_config_toml);
  ASSERT_TRUE(b.has_truth());
  EXPECT_EQ(b.truth_set_count(), a.truth_set_count());
  for (std::uint64_t i = 0; i < a.set_count(); ++i) {
    const FrameSet x = a.read_set(i), y = b.read_set(i);
    EXPECT_EQ(x.trigger_index, y.trigger_index);
    ASSERT_EQ(x.cameras.size(), y.cameras.size());
    for (std::size_t c = 0; c < x.cameras.size(); ++c) {
      const Image& p = x.cameras[c].b.image;
      const Image& q = y.cameras[c].b.image;
      ASSERT_EQ(p.width(), q.width());
      ASSERT_EQ(p.height(), q.height());
      for (int r = 0; r < p.height(); ++r)
        ASSERT_EQ(std::memcmp(p.row<std::uint16_t>(r), q.row<std::uint16_t>(r), sizeof(std::uint16_t) * p.width()), 0);
    }
    EXPECT_EQ(b.truth_set(i).particles_b.size(), a.truth_set(i).particles_b.size());
  }
}

TEST(StreamRecording, RefusesBadOptionsBeforeAnyFile) {
  TempDir tmp;
  rig::StreamRecordingOptions options;
  options.recorder.out = tmp / "r.h5";
  options.sets = 0;
  EXPECT_THROW(rig::StreamRecording{options}, Error);
  options.sets.reset();
  options.idle_timeout_s = -1;
  EXPECT_THROW(rig::StreamRecording{options}, Error);
  options.idle_timeout_s = 0;  // wait for ever: valid
  options.compression = "zip";
  EXPECT_THROW(rig::StreamRecording{options}, Error);
  EXPECT_FALSE(std::filesystem::exists(tmp / "r.h5"));
}

}  // namespace
}  // namespace tomorig::testing
