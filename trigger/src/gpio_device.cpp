// The gpio backend: a schedule of (time, line, level) per period, played on the clock.
#include "tomorig/trigger/gpio_device.h"

#include <algorithm>
#include <tuple>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::trigger {
namespace {

struct ScheduledEdge {
  std::int64_t time_ns;
  std::size_t line;  // index into the requested lines
  bool high;
};

class GpioBackend final : public DeviceBackend {
 public:
  GpioBackend(std::unique_ptr<GpioLines> lines, const GpioTriggerOptions& options)
      : lines_(std::move(lines)), options_(options) {
    if (!lines_) throw bad_input("gpio trigger: no GPIO lines given");
    if (options_.resolution_ns <= 0)
      throw bad_input(fmt::format("gpio trigger: resolution {} ns must be > 0", options_.resolution_ns));
    if (!options_.clock) options_.clock = steady_clock();
  }
  ~GpioBackend() override {
    try {
      lines_->release();
    } catch (...) {  // nothing sensible to do while destroying
    }
  }

  DeviceCapabilities capabilities() const override { return gpio_capabilities(options_); }

  void arm(const TimingPlan& plan) override {
    std::vector<GpioLineId> ids;
    std::vector<ScheduledEdge> schedule;
    for (const auto& ch : plan.channels) {
      if (!ch.spec.wired()) continue;  // made by the external pulse generator
      const std::size_t index = ids.size();
      ids.push_back({ch.spec.chip, static_cast<unsigned>(ch.spec.line)});
      for (const auto& p : ch.pulses) {
        schedule.push_back({p.rise_ns, index, true});
        schedule.push_back({p.fall_ns, index, false});
      }
    }
    // At equal times a line goes low before another goes high: never two outputs high longer
    // than planned.
    std::sort(schedule.begin(), schedule.end(), [](const ScheduledEdge& a, const ScheduledEdge& b) {
      return std::tie(a.time_ns, a.high, a.line) < std::tie(b.time_ns, b.high, b.line);
    });
    lines_->request(ids, options_.consumer);
    line_count_ = ids.size();
    schedule_ = std::move(schedule);
    period_ns_ = plan.period_ns;
    dt_ns_ = plan.dt_ns;
    pulse1_offset_ns_ = (plan.light_pulse_1.rise_ns + plan.light_pulse_1.fall_ns) / 2;
  }

  void begin() override { origin_ns_ = options_.clock->now_ns(); }

  std::optional<TriggerEvent> fire(std::uint64_t k, std::stop_token stop) override {
    const std::int64_t start = origin_ns_ + static_cast<std::int64_t>(k) * period_ns_;
    if (!options_.clock->wait_until_ns(start, stop)) return std::nullopt;
    TriggerEvent event;
    event.index = k;
    event.timestamp_ns = options_.clock->now_ns() - origin_ns_;
    event.dt_ns = dt_ns_;  // made by the plan's timing (or the pulse generator); not measurable here
    event.pulse1_ns = event.timestamp_ns + pulse1_offset_ns_;
    for (const auto& edge : schedule_) {
      if (!options_.clock->wait_until_ns(start + edge.time_ns, stop)) return std::nullopt;
      lines_->set(edge.line, edge.high);
    }
    return event;
  }

  void end() override {
    for (std::size_t i = 0; i < line_count_; ++i) lines_->set(i, false);
  }

  bool paced() const override { return true; }

 private:
  std::unique_ptr<GpioLines> lines_;
  GpioTriggerOptions options_;
  std::vector<ScheduledEdge> schedule_;
  std::size_t line_count_ = 0;
  std::int64_t period_ns_ = 0;
  std::int64_t dt_ns_ = 0;
  std::int64_t pulse1_offset_ns_ = 0;
  std::int64_t origin_ns_ = 0;
};

}  // namespace

DeviceCapabilities gpio_capabilities(const GpioTriggerOptions& options) {
  DeviceCapabilities caps;
  caps.device = "gpio";
  caps.max_channels = options.max_lines;
  caps.resolution_ns = options.resolution_ns;
  caps.jitter_ns = options.jitter_ns;
  caps.min_pulse_ns = options.resolution_ns;
  caps.drives_unwired_channels = false;
  return caps;
}

std::unique_ptr<DeviceBackend> make_gpio_backend(std::unique_ptr<GpioLines> lines, const GpioTriggerOptions& options) {
  return std::make_unique<GpioBackend>(std::move(lines), options);
}

std::unique_ptr<TriggerDevice> make_gpio_device(const GpioTriggerOptions& options,
                                                std::vector<LightSource> light_sources) {
  return std::make_unique<TriggerDevice>(make_gpio_backend(make_libgpiod_lines(), options), std::move(light_sources));
}

}  // namespace tomorig::trigger
