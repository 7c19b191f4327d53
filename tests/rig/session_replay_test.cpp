// rig::SessionReplay: a recorded session sent on the lossless stream, checked by a receiver
// against the session file itself (every set, its truth, the framing, the pixels).
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include <zmq.hpp>

#include "binding_receiver.h"
#include "temp_dir.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/rig_runner.h"
#include "tomorig/rig/session_replay.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/frame_receiver.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::testing {
namespace {

// A simulated rig's session of `sets` sets, with truth.
std::filesystem::path record_session(const TempDir& tmp, std::uint64_t sets) {
  rig::RigRunOptions options;
  options.acquisition.sets = sets;
  options.acquisition.pacing = trigger::Pacing::as_fast_as_consumed;
  options.recorder.out = tmp / "recorded.h5";
  options.status_endpoint = "none";
  rig::RigRunner(config::default_rig_config(), options).run();
  return tmp / "recorded.h5";
}

TEST(SessionReplay, SendsTheChosenSetsFramedAsASessionWithTheirTruthAndPixels) {
  TempDir tmp;
  const std::filesystem::path file = record_session(tmp, 4);
  BindingReceiver receiver;
  rig::SessionReplayOptions options;
  options.session = file;
  options.to = receiver.endpoint();
  options.connect = true;
  options.rate = "max";
  options.sets = "1:3";
  rig::SessionReplay replay(options);
  EXPECT_EQ(replay.range().first, 1u);
  EXPECT_EQ(replay.range().last, 3u);
  std::string announced;
  std::vector<std::uint64_t> handed;
  const rig::SessionReplayReport report = replay.run({
      .sending = [&](const std::string& endpoint) { announced = endpoint; },
      .sent = [&](const FrameSet& set) { handed.push_back(set.set_index); },
  });
  const Received& got = receiver.wait();
  ASSERT_TRUE(got.error.empty()) << got.error;

  EXPECT_EQ(announced, receiver.endpoint());
  EXPECT_EQ(report.endpoint, receiver.endpoint());
  EXPECT_TRUE(report.announced);
  EXPECT_FALSE(report.stopped);
  EXPECT_TRUE(report.failure.empty()) << report.failure;
  EXPECT_EQ(report.sets_sent, 2u);
  EXPECT_EQ(handed, (std::vector<std::uint64_t>{1, 2}));
  EXPECT_NE(report.brief().find("replayed 2 sets"), std::string::npos) << report.brief();

  const storage::SessionReader session(file);
  ASSERT_FALSE(got.messages.empty());
  const auto* start = std::get_if<stream::SessionStart>(&got.messages.front());
  ASSERT_NE(start, nullptr) << "the session start comes first";
  EXPECT_EQ(start->info.rig_config_toml, session.info().rig_config_toml);
  EXPECT_TRUE(start->truth.has_value());
  const auto* end = std::get_if<stream::SessionEnd>(&got.messages.back());
  ASSERT_NE(end, nullptr) << "the session end comes last";
  EXPECT_EQ(end->sets_sent, 2u);
  EXPECT_EQ(end->outcome, stream::SessionOutcome::completed);

  const auto sets = all_of<FrameSet>(got.messages);
  const auto truths = all_of<stream::SetTruth>(got.messages);
  ASSERT_EQ(sets.size(), 2u);
  ASSERT_EQ(truths.size(), 2u);
  for (std::size_t k = 0; k < sets.size(); ++k) {
    const FrameSet recorded = session.read_set(1 + k);
    EXPECT_EQ(sets[k]->set_index, 1 + k);
    EXPECT_EQ(sets[k]->trigger_index, recorded.trigger_index);
    EXPECT_EQ(truths[k]->trigger_index, recorded.trigger_index);
    EXPECT_EQ(truths[k]->particles.particles_a.size(), session.truth_set(1 + k).particles_a.size());
    ASSERT_EQ(sets[k]->cameras.size(), recorded.cameras.size());
    for (std::size_t c = 0; c < recorded.cameras.size(); ++c) {
      const Image& a = sets[k]->cameras[c].a.image;
      const Image& b = recorded.cameras[c].a.image;
      ASSERT_EQ(a.height(), b.height());
      ASSERT_EQ(a.width(), b.width());
      for (int y = 0; y < a.height(); ++y)
        ASSERT_EQ(std::memcmp(a.row<std::uint16_t>(y), b.row<std::uint16_t>(y), sizeof(std::uint16_t) * a.width()), 0)
            << "set " << 1 + k << " camera " << c << " row " << y;
    }
  }
}

TEST(SessionReplay, RefusesBadOptionsBeforeAnySocketExists) {
  TempDir tmp;
  const std::filesystem::path file = record_session(tmp, 2);
  rig::SessionReplayOptions options;
  options.session = file;
  options.timeout_s = 0;
  EXPECT_THROW(rig::SessionReplay{options}, Error);
  options.timeout_s = 10;
  options.sets = "5:9";
  EXPECT_THROW(rig::SessionReplay{options}, Error);
  options.sets = "";
  options.rate = "fast";
  EXPECT_THROW(rig::SessionReplay{options}, Error);
  options.rate = "max";
  options.session = tmp / "missing.h5";
  EXPECT_THROW(rig::SessionReplay{options}, Error);
}

}  // namespace
}  // namespace tomorig::testing
