// From the rig config to timing inputs: what the [trigger] table says is used, and what it
// does not say takes documented, safe defaults.
#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/trigger/rig_trigger.h"

namespace tomorig::trigger {
namespace {

TEST(RigTrigger, DefaultRigMapsEveryChannel) {
  const RigTrigger t = rig_trigger(config::default_rig_config());
  EXPECT_EQ(t.backend, config::TriggerBackend::simulated);
  EXPECT_DOUBLE_EQ(t.inputs.rate_hz, 10.0);
  EXPECT_EQ(t.inputs.dt_ns, 100'000);
  ASSERT_EQ(t.inputs.channels.size(), 2u);
  EXPECT_EQ(t.inputs.channels[0].name, "laser");
  EXPECT_EQ(t.inputs.channels[0].role, ChannelRole::light);
  EXPECT_EQ(t.inputs.channels[1].role, ChannelRole::camera);
  ASSERT_EQ(t.inputs.light_sources.size(), 1u);
  EXPECT_EQ(t.inputs.light_sources[0].pulse_width_ns, 10);
  EXPECT_EQ(t.inputs.light_sources[0].kind, LightSourceKind::laser);
  const TimingPlan plan = plan_and_check(t);
  EXPECT_EQ(plan.dt_ns, 100'000);
  // And a device made from it arms with that plan.
  auto device = make_trigger_device(t, Pacing::as_fast_as_consumed);
  EXPECT_NO_THROW(device->arm(plan));
}

TEST(RigTrigger, SimulatedRigWithoutChannelsGetsDefaults) {
  config::RigConfig rig = config::default_rig_config();
  rig.trigger.channels.clear();
  rig.trigger.jitter_ns = 3.0;
  const RigTrigger t = rig_trigger(rig);
  ASSERT_EQ(t.inputs.channels.size(), 2u);
  EXPECT_EQ(t.inputs.channels[0].name, "cameras");
  EXPECT_EQ(t.inputs.channels[1].name, "light");
  EXPECT_DOUBLE_EQ(t.simulated.jitter_ns, 3.0);
  EXPECT_NO_THROW(plan_and_check(t));
}

TEST(RigTrigger, UnsafeRateRefusedByPlanAndCheck) {
  config::RigConfig rig = config::default_rig_config();
  rig.trigger.rate_hz = 40.0;  // above the 30 Hz of a source of unknown kind
  try {
    plan_and_check(rig_trigger(rig));
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("max_rate_hz"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::trigger
