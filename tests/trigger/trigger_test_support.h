#pragma once
// Shared by the trigger tests: timing inputs of typical rigs, a virtual clock (waits return at
// once, time jumps to the deadline) and a fake GpioLines that records every edge.
#include <atomic>
#include <condition_variable>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/trigger/clock.h"
#include "tomorig/trigger/gpio_device.h"
#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger::test {

// Tomographic shadowgraphy: one LED making both pulses, one camera trigger.
inline TimingInputs led_rig() {
  TimingInputs in;
  in.rate_hz = 10.0;
  in.dt_ns = 100'000;
  in.camera = {20'000, 120, 1'000'000};
  in.light_sources = {{"led1", LightSourceKind::led, 1'000, 0, {}}};
  ChannelSpec cam;
  cam.name = "cam";
  cam.role = ChannelRole::camera;
  cam.delay_ns = 1'000;
  cam.width_ns = 10'000;
  ChannelSpec led;
  led.name = "led1";
  led.role = ChannelRole::light;
  led.light_source = "led1";
  led.pulses = PulseSelect::both;
  led.delay_ns = 50;  // driver rise time
  in.channels = {cam, led};
  return in;
}

// Tomographic PIV: a dual-cavity Nd:YAG, each head with a flash lamp and a Q-switch channel.
inline TimingInputs laser_rig() {
  TimingInputs in;
  in.rate_hz = 10.0;
  in.dt_ns = 2'000;
  in.camera = {10'000, 120, 1'000'000};
  in.light_sources = {{"head1", LightSourceKind::laser, 10, 180'000, {}},
                      {"head2", LightSourceKind::laser, 10, 180'000, {}}};
  auto channel = [](std::string name, ChannelRole role, std::string source, PulseSelect pulses, std::int64_t delay) {
    ChannelSpec c;
    c.name = std::move(name);
    c.role = role;
    c.light_source = std::move(source);
    c.pulses = pulses;
    c.delay_ns = delay;
    return c;
  };
  in.channels = {channel("cam", ChannelRole::camera, "", PulseSelect::both, 1'000),
                 channel("fl1", ChannelRole::flashlamp, "head1", PulseSelect::first, 0),
                 channel("qs1", ChannelRole::light, "head1", PulseSelect::first, 100),
                 channel("fl2", ChannelRole::flashlamp, "head2", PulseSelect::second, 0),
                 channel("qs2", ChannelRole::light, "head2", PulseSelect::second, 100)};
  return in;
}

// Starts at 1 s. A wait returns at once with the time advanced to its deadline, unless the
// deadline lies beyond `horizon_ns`: then it blocks until stop is requested (the future has not
// come yet), which lets a test stop a device at a known point without sleeping.
class VirtualClock final : public Clock {
 public:
  explicit VirtualClock(std::int64_t horizon_ns = std::numeric_limits<std::int64_t>::max()) : horizon_(horizon_ns) {}
  std::int64_t now_ns() override { return now_.load(); }
  bool wait_until_ns(std::int64_t t_ns, std::stop_token stop) override {
    if (t_ns > horizon_) {
      std::mutex m;
      std::condition_variable_any cv;
      std::unique_lock lock(m);
      cv.wait(lock, stop, [] { return false; });
      return false;
    }
    if (stop.stop_requested()) return false;
    if (t_ns > now_.load()) now_.store(t_ns);
    return true;
  }

 private:
  std::atomic<std::int64_t> now_{1'000'000'000};
  std::int64_t horizon_;
};

struct RecordedEdge {
  std::int64_t time_ns;
  std::string chip;
  unsigned offset;
  bool high;
  bool operator==(const RecordedEdge&) const = default;
};

// What the fake saw; shared with the test after the fake moved into a device.
struct GpioRecord {
  std::mutex mutex;
  std::vector<RecordedEdge> edges;
  std::vector<GpioLineId> requested;
  std::string consumer;
  bool released = false;
};

class FakeGpioLines final : public GpioLines {
 public:
  FakeGpioLines(std::shared_ptr<Clock> clock, std::shared_ptr<GpioRecord> record, std::set<std::string> chips)
      : clock_(std::move(clock)), record_(std::move(record)), chips_(std::move(chips)) {}

  void request(const std::vector<GpioLineId>& lines, const std::string& consumer) override {
    for (const auto& l : lines)
      if (!chips_.count(l.chip)) throw runtime_error(fmt::format("GPIO chip '{}' cannot be opened (fake)", l.chip));
    std::lock_guard lock(record_->mutex);
    record_->requested = lines;
    record_->consumer = consumer;
    record_->released = false;
  }
  void set(std::size_t index, bool high) override {
    std::lock_guard lock(record_->mutex);
    const auto& id = record_->requested.at(index);
    record_->edges.push_back({clock_->now_ns(), id.chip, id.offset, high});
  }
  void release() override {
    std::lock_guard lock(record_->mutex);
    record_->released = true;
  }

 private:
  std::shared_ptr<Clock> clock_;
  std::shared_ptr<GpioRecord> record_;
  std::set<std::string> chips_;
};

}  // namespace tomorig::trigger::test
