// The gpio device against a fake GpioLines on a virtual clock: the exact edge sequence, the
// refusal of µs timing without an external pulse generator, and clear errors for a missing chip.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "tomorig/core/error.h"
#include "tomorig/trigger/gpio_device.h"
#include "trigger_test_support.h"

namespace tomorig::trigger {
namespace {

using test::FakeGpioLines;
using test::GpioRecord;
using test::RecordedEdge;
using test::VirtualClock;

constexpr std::int64_t kMs = 1'000'000;
constexpr std::int64_t kClockStart = 1'000 * kMs;  // VirtualClock's first reading

// Millisecond scale, what userspace GPIO can time: a camera trigger and a gated light (a CW
// LED switched by a gate, with limits configured for it), dt 5 ms.
TimingInputs gate_rig(const std::string& chip = "gpiochip0") {
  TimingInputs in;
  in.rate_hz = 10.0;
  in.dt_ns = 5 * kMs;
  in.camera = {4 * kMs, 120, 50 * kMs};
  LightSource gate{"gate", LightSourceKind::led, 1 * kMs, 0, {}};
  gate.limits = {2 * kMs, 0.05, 100.0};
  in.light_sources = {gate};
  ChannelSpec cam;
  cam.name = "cam";
  cam.role = ChannelRole::camera;
  cam.width_ns = 1 * kMs;
  cam.chip = chip;
  cam.line = 3;
  ChannelSpec light;
  light.name = "gate";
  light.role = ChannelRole::light;
  light.light_source = "gate";
  light.chip = chip;
  light.line = 4;
  in.channels = {cam, light};
  return in;
}

struct Rig {
  std::shared_ptr<VirtualClock> clock;
  std::shared_ptr<GpioRecord> record = std::make_shared<GpioRecord>();
  std::unique_ptr<TriggerDevice> device;
};

Rig make_rig(const TimingInputs& in, std::int64_t horizon_ns = std::numeric_limits<std::int64_t>::max()) {
  Rig rig;
  rig.clock = std::make_shared<VirtualClock>(horizon_ns);
  GpioTriggerOptions options;
  options.clock = rig.clock;
  auto lines = std::make_unique<FakeGpioLines>(rig.clock, rig.record, std::set<std::string>{"gpiochip0"});
  rig.device = std::make_unique<TriggerDevice>(make_gpio_backend(std::move(lines), options), in.light_sources);
  return rig;
}

std::string arm_error(TriggerDevice& device, const TimingPlan& plan) {
  try {
    device.arm(plan);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "armed";
  return {};
}

TEST(GpioDevice, PlaysTheEdgeSequenceOfEachPeriod) {
  const TimingInputs in = gate_rig();
  Rig rig = make_rig(in);
  rig.device->arm(plan_timing(in));
  rig.device->start(3);
  std::vector<TriggerEvent> events;
  while (auto e = rig.device->next_event()) events.push_back(*e);

  ASSERT_EQ(events.size(), 3u);
  for (std::uint64_t k = 0; k < 3; ++k) {
    EXPECT_EQ(events[k].index, k);
    EXPECT_EQ(events[k].timestamp_ns, static_cast<std::int64_t>(k) * 100 * kMs);
    EXPECT_EQ(events[k].dt_ns, 5 * kMs);
    EXPECT_EQ(events[k].pulse1_ns, events[k].timestamp_ns + 2 * kMs);  // the gate's first centre
  }
  std::vector<RecordedEdge> expected;
  for (std::int64_t k = 0; k < 3; ++k) {
    const std::int64_t t0 = kClockStart + k * 100 * kMs;
    // By hand: frame A ends midway in [0.5, 3.5] ms after pulse 1's centre, so the camera
    // (4 ms exposure, 1 ms trigger) fires 2 ms before it; the gate is 1 ms wide around each centre.
    expected.push_back({t0, "gpiochip0", 3, true});
    expected.push_back({t0 + 1 * kMs, "gpiochip0", 3, false});
    expected.push_back({t0 + 1'500'000, "gpiochip0", 4, true});
    expected.push_back({t0 + 2'500'000, "gpiochip0", 4, false});
    expected.push_back({t0 + 6'500'000, "gpiochip0", 4, true});
    expected.push_back({t0 + 7'500'000, "gpiochip0", 4, false});
  }
  std::lock_guard lock(rig.record->mutex);
  ASSERT_GE(rig.record->edges.size(), expected.size());
  EXPECT_EQ(std::vector<RecordedEdge>(rig.record->edges.begin(), rig.record->edges.begin() + expected.size()),
            expected);
  for (std::size_t i = expected.size(); i < rig.record->edges.size(); ++i)
    EXPECT_FALSE(rig.record->edges[i].high);  // after the run: lines low
  EXPECT_EQ(rig.record->consumer, "tomorig");
  ASSERT_EQ(rig.record->requested.size(), 2u);
  EXPECT_EQ(rig.record->requested[1].offset, 4u);
}

TEST(GpioDevice, RefusesMicrosecondDtWithoutAPulseGenerator) {
  TimingInputs in = test::led_rig();  // dt 100 µs, 1 µs LED pulses
  for (auto& c : in.channels) c.chip = "gpiochip0", c.line = c.role == ChannelRole::camera ? 1 : 2;
  Rig rig = make_rig(in);
  const std::string m = arm_error(*rig.device, plan_timing(in));
  EXPECT_NE(m.find("dt 100 us is below the gpio device's time resolution of 1000 us"), std::string::npos) << m;
  EXPECT_NE(m.find("pulse_generator"), std::string::npos) << m;
  EXPECT_FALSE(rig.device->armed());
  std::lock_guard lock(rig.record->mutex);
  EXPECT_TRUE(rig.record->requested.empty());  // refused before claiming a line
}

TEST(GpioDevice, AnExternalPulseGeneratorMakesTheMicrosecondPulses) {
  TimingInputs in = test::led_rig();  // camera and LED unwired: the generator makes them
  ChannelSpec gen;
  gen.name = "generator";
  gen.role = ChannelRole::pulse_generator;
  gen.width_ns = 1 * kMs;
  gen.chip = "gpiochip0";
  gen.line = 5;
  in.channels.push_back(gen);
  Rig rig = make_rig(in);
  rig.device->arm(plan_timing(in));
  rig.device->start(2);
  int n = 0;
  while (rig.device->next_event()) ++n;
  EXPECT_EQ(n, 2);
  std::lock_guard lock(rig.record->mutex);
  ASSERT_EQ(rig.record->requested.size(), 1u);  // only the generator's trigger input
  EXPECT_EQ(rig.record->requested[0].offset, 5u);
  const std::vector<RecordedEdge> expected = {{kClockStart, "gpiochip0", 5, true},
                                              {kClockStart + kMs, "gpiochip0", 5, false},
                                              {kClockStart + 100 * kMs, "gpiochip0", 5, true},
                                              {kClockStart + 101 * kMs, "gpiochip0", 5, false}};
  ASSERT_GE(rig.record->edges.size(), expected.size());
  EXPECT_EQ(std::vector<RecordedEdge>(rig.record->edges.begin(), rig.record->edges.begin() + 4), expected);
}

TEST(GpioDevice, UnwiredPulseGeneratorIsRefused) {
  TimingInputs in = test::led_rig();
  ChannelSpec gen;
  gen.name = "generator";
  gen.role = ChannelRole::pulse_generator;
  in.channels.push_back(gen);
  Rig rig = make_rig(in);
  const std::string m = arm_error(*rig.device, plan_timing(in));
  EXPECT_NE(m.find("pulse_generator channel 'generator' has no gpio output"), std::string::npos) << m;
}

TEST(GpioDevice, MissingChipIsNamed) {
  const TimingInputs in = gate_rig("gpiochip9");
  Rig rig = make_rig(in);
  const std::string m = arm_error(*rig.device, plan_timing(in));
  EXPECT_NE(m.find("'gpiochip9'"), std::string::npos) << m;
}

TEST(GpioDevice, MissingChipIsNamedByLibgpiod) {
  // This machine has no GPIO chips at all; real libgpiod must say which chip is missing.
  auto lines = make_libgpiod_lines();
  try {
    lines->request({{"tomorig-no-such-chip", 3}}, "tomorig-test");
    FAIL() << "a missing chip was opened";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::runtime);
    EXPECT_NE(std::string(e.what()).find("GPIO chip 'tomorig-no-such-chip' cannot be opened"), std::string::npos)
        << e.what();
  }
  // And through a real gpio device.
  const TimingInputs in = gate_rig("tomorig-no-such-chip");
  GpioTriggerOptions options;
  auto device = make_gpio_device(options, in.light_sources);
  const std::string m = arm_error(*device, plan_timing(in));
  EXPECT_NE(m.find("'tomorig-no-such-chip'"), std::string::npos) << m;
}

TEST(GpioDevice, StopEndsAContinuousRunWithLinesLow) {
  const TimingInputs in = gate_rig();
  // The virtual future ends after 5 periods: the device fires events 0-4, then waits.
  Rig rig = make_rig(in, kClockStart + 4 * 100 * kMs + 50 * kMs);
  rig.device->arm(plan_timing(in));
  rig.device->start(std::nullopt);
  for (std::uint64_t k = 0; k < 5; ++k) {
    const auto e = rig.device->next_event();
    ASSERT_TRUE(e);
    EXPECT_EQ(e->index, k);
  }
  rig.device->stop();
  EXPECT_FALSE(rig.device->next_event());
  std::lock_guard lock(rig.record->mutex);
  EXPECT_EQ(rig.record->edges.size(), 5u * 6u + 2u);  // 5 periods, then both lines set low
  std::map<unsigned, bool> last;
  for (const auto& e : rig.record->edges) last[e.offset] = e.high;
  EXPECT_EQ(last.size(), 2u);
  for (const auto& [offset, high] : last) EXPECT_FALSE(high) << "line " << offset;
}

}  // namespace
}  // namespace tomorig::trigger
