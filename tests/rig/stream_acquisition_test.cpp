// rig::StreamAcquisition: the simulated rig acquired and sent on the lossless stream, checked by a
// receiver against the rig file (cameras, image sizes, pulse separation) and the stream's framing
// (session start with truth, each set's truth before the set, the session end).
#include <gtest/gtest.h>

#include <csignal>
#include <cmath>
#include <string>
#include <variant>
#include <vector>

#include "binding_receiver.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/stop_signal.h"
#include "tomorig/rig/stream_acquisition.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::testing {
namespace {

rig::StreamAcquisitionOptions options_to(const std::string& endpoint, std::uint64_t sets) {
  rig::StreamAcquisitionOptions options;
  options.acquisition.sets = sets;
  options.acquisition.pacing = trigger::Pacing::as_fast_as_consumed;
  options.to = endpoint;
  options.connect = true;  // the test's receiver binds
  options.status_endpoint = "none";
  options.wait_s = 10;
  return options;
}

TEST(StreamAcquisition, SendsTheRigsSetsFramedAsASessionWithTheirTruth) {
  const config::RigConfig rig = config::default_rig_config();
  BindingReceiver receiver;
  rig::StreamAcquisition acquisition(rig, options_to(receiver.endpoint(), 3));
  std::string announced;
  std::vector<std::uint64_t> handed;
  const rig::StreamAcquisitionReport report = acquisition.run({
      .sending = [&](const std::string& endpoint) { announced = endpoint; },
      .sent = [&](const FrameSet& set) { handed.push_back(set.trigger_index); },
  });
  const Received& got = receiver.wait();
  ASSERT_TRUE(got.error.empty()) << got.error;

  EXPECT_EQ(announced, receiver.endpoint());
  EXPECT_TRUE(report.announced);
  EXPECT_EQ(report.sets_sent, 3u);
  EXPECT_EQ(report.frames_lost, 0u);
  EXPECT_EQ(report.incomplete_sets, 0u);
  EXPECT_TRUE(report.failure.empty()) << report.failure;
  EXPECT_TRUE(report.stopped_by.empty());
  EXPECT_EQ(handed.size(), 3u);
  EXPECT_NE(report.brief().find("acquired and sent 3 sets"), std::string::npos) << report.brief();

  ASSERT_FALSE(got.messages.empty());
  const auto* start = std::get_if<stream::SessionStart>(&got.messages.front());
  ASSERT_NE(start, nullptr) << "the session start comes first";
  EXPECT_EQ(start->info.rig_config_toml, rig.source_text);
  ASSERT_EQ(start->info.cameras.size(), rig.cameras.size());
  EXPECT_TRUE(start->truth.has_value()) << "a simulated rig sends its truth";
  const auto* end = std::get_if<stream::SessionEnd>(&got.messages.back());
  ASSERT_NE(end, nullptr) << "the session end comes last";
  EXPECT_EQ(end->session_id, start->session_id);
  EXPECT_EQ(end->sets_sent, 3u);
  EXPECT_EQ(end->outcome, stream::SessionOutcome::completed);

  // Each set comes right after its own truth, and carries every camera of the rig file at its
  // configured size, exposed with the configured pulse separation.
  std::size_t sets = 0;
  for (std::size_t k = 1; k + 1 < got.messages.size(); ++k) {
    const auto* set = std::get_if<FrameSet>(&got.messages[k]);
    if (!set) continue;
    ++sets;
    const auto* truth = std::get_if<stream::SetTruth>(&got.messages[k - 1]);
    ASSERT_NE(truth, nullptr) << "set " << set->trigger_index << " without its truth before it";
    EXPECT_EQ(truth->session_id, start->session_id);
    EXPECT_EQ(truth->trigger_index, set->trigger_index);
    EXPECT_FALSE(truth->particles.particles_a.empty());
    EXPECT_NEAR(static_cast<double>(set->dt_ns), rig.trigger.dt_us * 1e3, 6 * rig.trigger.jitter_ns + 1);
    ASSERT_EQ(set->cameras.size(), rig.cameras.size());
    for (std::size_t c = 0; c < rig.cameras.size(); ++c) {
      EXPECT_EQ(set->cameras[c].camera_id, rig.cameras[c].id);
      EXPECT_EQ(set->cameras[c].a.image.width(), rig.cameras[c].roi.width);
      EXPECT_EQ(set->cameras[c].b.image.height(), rig.cameras[c].roi.height);
    }
  }
  EXPECT_EQ(sets, 3u);
}

TEST(StreamAcquisition, CountsAVanishedCameraAndGoesOnWhenAskedTo) {
  BindingReceiver receiver;
  rig::StreamAcquisitionOptions options = options_to(receiver.endpoint(), 4);
  rig::add_camera_fault(options.acquisition.faults, "cam2:vanish-after=2");
  options.acquisition.on_camera_loss = rig::CameraLossPolicy::continue_;
  rig::StreamAcquisition acquisition(config::default_rig_config(), options);
  std::vector<std::string> notices;
  const rig::StreamAcquisitionReport report =
      acquisition.run({.notice = [&](const std::string& text) { notices.push_back(text); }});
  const Received& got = receiver.wait();
  ASSERT_TRUE(got.error.empty()) << got.error;
  EXPECT_EQ(report.sets_sent, 4u);
  EXPECT_EQ(report.frames_lost, 4u);  // both frames of cam2 in sets 2 and 3
  EXPECT_EQ(report.incomplete_sets, 2u);
  EXPECT_TRUE(report.failure.empty()) << report.failure;
  bool told = false;
  for (const auto& text : notices) told |= text.find("cam2 vanished") != std::string::npos;
  EXPECT_TRUE(told) << "the operator hears of the vanished camera";
  EXPECT_EQ(all_of<FrameSet>(got.messages).size(), 4u);
}

TEST(StreamAcquisition, ALostCameraUnderTheStopPolicyEndsTheSessionAsFailed) {
  BindingReceiver receiver;
  rig::StreamAcquisitionOptions options = options_to(receiver.endpoint(), 6);
  rig::add_camera_fault(options.acquisition.faults, "cam1:vanish-after=2");
  rig::StreamAcquisition acquisition(config::default_rig_config(), options);
  const rig::StreamAcquisitionReport report = acquisition.run();
  const Received& got = receiver.wait();
  ASSERT_TRUE(got.error.empty()) << got.error;
  EXPECT_FALSE(report.failure.empty());
  EXPECT_LT(report.sets_sent, 6u);
  const auto* end = std::get_if<stream::SessionEnd>(&got.messages.back());
  ASSERT_NE(end, nullptr);
  EXPECT_EQ(end->outcome, stream::SessionOutcome::failed);
  EXPECT_EQ(end->reason, report.failure);
  EXPECT_EQ(end->sets_sent, report.sets_sent);
}

TEST(StreamAcquisition, RefusesBadOptionsBeforeAnySocketExists) {
  rig::StreamAcquisitionOptions options = options_to("tcp://127.0.0.1:*", 1);
  options.timeout_s = 0;
  try {
    rig::StreamAcquisition acquisition(config::default_rig_config(), options);
    FAIL() << "a zero timeout was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("--timeout 0"), std::string::npos) << e.what();
  }
  options.timeout_s = 1;
  options.wait_s = -1;
  EXPECT_THROW(rig::StreamAcquisition(config::default_rig_config(), options), Error);
}

TEST(StreamAcquisition, NoRecorderWithinTheWaitIsARuntimeErrorNamingTheEndpoint) {
  rig::StreamAcquisitionOptions options = options_to("tcp://127.0.0.1:*", 1);
  options.connect = false;  // bind, and nobody connects
  options.wait_s = 0.3;
  rig::StreamAcquisition acquisition(config::default_rig_config(), options);
  std::string endpoint;
  try {
    acquisition.run({.sending = [&](const std::string& e) { endpoint = e; }});
    FAIL() << "acquired without a recorder";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::runtime);
    EXPECT_NE(std::string(e.what()).find("no recorder connected to " + endpoint), std::string::npos) << e.what();
  }
}

TEST(StreamAcquisition, AStopWhileWaitingForARecorderAcquiresNothing) {
  rig::StreamAcquisitionOptions options = options_to("tcp://127.0.0.1:*", 5);
  options.connect = false;
  rig::StreamAcquisition acquisition(config::default_rig_config(), options);
  const rig::StopSignalGuard stop;
  std::raise(SIGINT);  // caught by the guard: a stop request, as Ctrl-C makes it
  const rig::StreamAcquisitionReport report = acquisition.run({.stop = &stop});
  EXPECT_FALSE(report.announced);
  EXPECT_EQ(report.sets_sent, 0u);
  EXPECT_EQ(report.stopped_by, "SIGINT");
  EXPECT_EQ(acquisition.acquisition().progress().trigger_events, 0u) << "the trigger never started";
  EXPECT_NE(report.brief().find("stopped by SIGINT before acquiring"), std::string::npos) << report.brief();
}

}  // namespace
}  // namespace tomorig::testing
