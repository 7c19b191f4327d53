// The simulated trigger device: exact indices and timestamps, bounded jitter statistics,
// reproducible with a seed, and stop() ends a continuous run. Synchronised only through the
// device's blocking event queue.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/trigger/simulated_device.h"
#include "trigger_test_support.h"

namespace tomorig::trigger {
namespace {

std::vector<TriggerEvent> run_all(TriggerDevice& device, std::uint64_t n) {
  device.start(n);
  std::vector<TriggerEvent> events;
  while (auto e = device.next_event()) events.push_back(*e);
  return events;
}

std::unique_ptr<TriggerDevice> armed_device(const SimulatedTriggerOptions& options, const TimingInputs& in) {
  auto device = make_simulated_device(options, in.light_sources);
  device->arm(plan_timing(in));
  return device;
}

TEST(SimulatedDevice, ExactTimestampsWithoutJitter) {
  TimingInputs in = test::led_rig();
  in.rate_hz = 3.0;  // a period that is not a whole number of ns: timestamps must not drift
  auto device = armed_device({}, in);
  const auto events = run_all(*device, 1000);
  ASSERT_EQ(events.size(), 1000u);
  for (std::uint64_t k = 0; k < events.size(); ++k) {
    EXPECT_EQ(events[k].index, k);
    EXPECT_EQ(events[k].timestamp_ns, std::llround(static_cast<double>(k) * 1e9 / 3.0));
    EXPECT_EQ(events[k].dt_ns, 100'000);
    // Pulse 1 is centred 11 µs after the period start in the LED rig (timing_plan_test).
    EXPECT_EQ(events[k].pulse1_ns, events[k].timestamp_ns + 11'000);
  }
  EXPECT_EQ(events.back().timestamp_ns, 333'000'000'000);
}

TEST(SimulatedDevice, JitterStatisticsAreBounded) {
  SimulatedTriggerOptions options;
  options.jitter_ns = 20.0;
  options.seed = 7;
  auto device = armed_device(options, test::led_rig());
  const int n = 4000;
  const auto events = run_all(*device, n);
  ASSERT_EQ(events.size(), static_cast<std::size_t>(n));
  double sum_t = 0, sum_t2 = 0, sum_dt = 0, sum_dt2 = 0;
  for (const auto& e : events) {
    const double t = static_cast<double>(e.timestamp_ns - std::llround(static_cast<double>(e.index) * 1e8));
    const double d = static_cast<double>(e.dt_ns - 100'000);
    sum_t += t, sum_t2 += t * t, sum_dt += d, sum_dt2 += d * d;
  }
  const double mean_t = sum_t / n, sd_t = std::sqrt(sum_t2 / n - mean_t * mean_t);
  const double mean_dt = sum_dt / n, sd_dt = std::sqrt(sum_dt2 / n - mean_dt * mean_dt);
  // Standard errors: mean 20/sqrt(4000) = 0.32 ns, sd about 1.1 %: 5 sigma bounds.
  EXPECT_LT(std::abs(mean_t), 1.6);
  EXPECT_NEAR(sd_t, 20.0, 20.0 * 0.06);
  // dt = pulse 2 - pulse 1, two independent edges: sigma * sqrt(2).
  EXPECT_LT(std::abs(mean_dt), 2.3);
  EXPECT_NEAR(sd_dt, 20.0 * std::sqrt(2.0), 20.0 * std::sqrt(2.0) * 0.06);
}

TEST(SimulatedDevice, SameSeedSameEvents) {
  SimulatedTriggerOptions options;
  options.jitter_ns = 5.0;
  options.seed = 42;
  auto a = armed_device(options, test::led_rig());
  auto b = armed_device(options, test::led_rig());
  const auto ea = run_all(*a, 50), eb = run_all(*b, 50);
  ASSERT_EQ(ea.size(), eb.size());
  bool any_jitter = false;
  for (std::size_t i = 0; i < ea.size(); ++i) {
    EXPECT_EQ(ea[i].timestamp_ns, eb[i].timestamp_ns);
    EXPECT_EQ(ea[i].dt_ns, eb[i].dt_ns);
    any_jitter = any_jitter || ea[i].dt_ns != 100'000;
  }
  EXPECT_TRUE(any_jitter);
  // A second run on the same device repeats the sequence too.
  const auto again = run_all(*a, 50);
  EXPECT_EQ(again.back().dt_ns, ea.back().dt_ns);
}

TEST(SimulatedDevice, StopEndsAContinuousRun) {
  auto device = std::make_unique<TriggerDevice>(make_simulated_backend({}), test::led_rig().light_sources, 4);
  device->arm(plan_timing(test::led_rig()));
  device->start(std::nullopt);
  for (std::uint64_t k = 0; k < 10; ++k) {
    const auto e = device->next_event();
    ASSERT_TRUE(e);
    EXPECT_EQ(e->index, k);  // as fast as consumed: none skipped
  }
  device->stop();
  int left = 0;
  while (device->next_event()) ++left;
  EXPECT_LE(left, 4);  // at most a full queue
  EXPECT_EQ(device->dropped_events(), 0u);
  // Stopped means stopped: the queue stays empty.
  EXPECT_FALSE(device->next_event_for(std::chrono::milliseconds(1)));
}

TEST(SimulatedDevice, RealTimePacingOnAClock) {
  SimulatedTriggerOptions options;
  options.pacing = Pacing::real_time;
  options.clock = std::make_shared<test::VirtualClock>();
  auto device = std::make_unique<TriggerDevice>(make_simulated_backend(options), test::led_rig().light_sources, 2);
  device->arm(plan_timing(test::led_rig()));
  device->start(20);
  std::vector<TriggerEvent> events;
  while (auto e = device->next_event()) events.push_back(*e);
  // Paced events happen whether or not they are read: what the consumer missed is counted.
  EXPECT_EQ(events.size() + device->dropped_events(), 20u);
  for (std::size_t i = 1; i < events.size(); ++i) EXPECT_GT(events[i].index, events[i - 1].index);
  for (const auto& e : events) EXPECT_EQ(e.timestamp_ns, static_cast<std::int64_t>(e.index) * 100'000'000);
}

TEST(SimulatedDevice, RealTimeOnTheSteadyClock) {
  SimulatedTriggerOptions options;
  options.pacing = Pacing::real_time;
  TimingInputs in = test::led_rig();
  in.rate_hz = 1000.0;  // 5 events: 4 ms of real time
  in.camera.exposure_b_ns = 500'000;
  in.light_sources[0].limits.max_duty_cycle = 0.01;
  in.light_sources[0].limits.max_rate_hz = 1e4;
  auto device = armed_device(options, in);
  const auto events = run_all(*device, 5);
  ASSERT_EQ(events.size() + device->dropped_events(), 5u);
  EXPECT_EQ(events.front().index, 0u);
}

TEST(SimulatedDevice, UsageErrors) {
  auto device = make_simulated_device({}, test::led_rig().light_sources);
  EXPECT_THROW(device->start(1), Error);  // not armed
  device->arm(plan_timing(test::led_rig()));
  device->start(std::nullopt);
  EXPECT_THROW(device->start(1), Error);                               // already running
  EXPECT_THROW(device->arm(plan_timing(test::led_rig())), Error);      // armed while running
  device->stop();
  SimulatedTriggerOptions bad;
  bad.jitter_ns = -1.0;
  EXPECT_THROW(make_simulated_backend(bad), Error);
}

}  // namespace
}  // namespace tomorig::trigger

namespace tomorig::trigger {
namespace {

// A dropped event is still a real event: its set must get its own time and Δt, not zeros.
TEST(SimulatedDevice, DroppedEventsKeepTheirTimesForTheConsumer) {
  SimulatedTriggerOptions options;
  options.pacing = Pacing::real_time;
  options.clock = std::make_shared<test::VirtualClock>();
  auto device = std::make_unique<TriggerDevice>(make_simulated_backend(options), test::led_rig().light_sources, 2);
  device->arm(plan_timing(test::led_rig()));
  EXPECT_EQ(device->queue_capacity(), 2u);
  device->start(20);
  std::vector<TriggerEvent> events;
  while (auto e = device->next_event()) events.push_back(*e);
  const std::vector<TriggerEvent> dropped = device->take_dropped_events();
  ASSERT_EQ(dropped.size(), device->dropped_events());
  ASSERT_EQ(events.size() + dropped.size(), 20u);
  std::vector<bool> seen(20, false);
  for (const auto& e : events) seen[e.index] = true;
  for (std::size_t i = 0; i < dropped.size(); ++i) {
    const TriggerEvent& e = dropped[i];
    EXPECT_FALSE(seen[e.index]) << "event " << e.index << " both delivered and dropped";
    seen[e.index] = true;
    if (i > 0) EXPECT_GT(e.index, dropped[i - 1].index);  // oldest first
    EXPECT_EQ(e.timestamp_ns, static_cast<std::int64_t>(e.index) * 100'000'000);
    EXPECT_EQ(e.dt_ns, 100'000);
    EXPECT_EQ(e.pulse1_ns, e.timestamp_ns + 11'000);
  }
  EXPECT_TRUE(device->take_dropped_events().empty());  // each one is handed over once
  EXPECT_EQ(device->queued_events(), 0u);
}

}  // namespace
}  // namespace tomorig::trigger
