#include "tomorig/trigger/simulated_device.h"

#include <cmath>
#include <random>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::trigger {
namespace {

class SimulatedBackend final : public DeviceBackend {
 public:
  explicit SimulatedBackend(const SimulatedTriggerOptions& options) : options_(options) {
    if (!(std::isfinite(options.jitter_ns) && options.jitter_ns >= 0.0))
      throw bad_input(fmt::format("simulated trigger: jitter {} ns must be >= 0", options.jitter_ns));
    if (options_.pacing == Pacing::real_time && !options_.clock) options_.clock = steady_clock();
  }

  DeviceCapabilities capabilities() const override { return simulated_capabilities(options_); }

  void arm(const TimingPlan& plan) override {
    period_ns_ = plan.period_ns;
    // The exact rate when it agrees with the period (a plan from plan_timing()), else the
    // period is what was checked for safety and is what counts.
    const bool consistent = plan.rate_hz > 0.0 && std::llround(1e9 / plan.rate_hz) == plan.period_ns;
    rate_hz_ = consistent ? plan.rate_hz : 1e9 / static_cast<double>(plan.period_ns);
    dt_ns_ = plan.dt_ns;
    pulse1_offset_ns_ = (plan.light_pulse_1.rise_ns + plan.light_pulse_1.fall_ns) / 2;
  }

  void begin() override {
    rng_.seed(options_.seed);
    normal_.reset();
    if (options_.pacing == Pacing::real_time) origin_ns_ = options_.clock->now_ns();
  }

  std::optional<TriggerEvent> fire(std::uint64_t k, std::stop_token stop) override {
    // k / rate exactly (not k * rounded period), so long runs do not drift from the nominal rate.
    const std::int64_t nominal = std::llround(static_cast<double>(k) * 1e9 / rate_hz_);
    if (options_.pacing == Pacing::real_time && !options_.clock->wait_until_ns(origin_ns_ + nominal, stop))
      return std::nullopt;
    // Each edge jitters independently: the trigger, light pulse 1 and light pulse 2.
    const double trigger_jitter = draw(), pulse1 = draw(), pulse2 = draw();
    TriggerEvent event;
    event.index = k;
    event.timestamp_ns = nominal + std::llround(trigger_jitter);
    event.dt_ns = dt_ns_ + std::llround(pulse2 - pulse1);
    event.pulse1_ns = nominal + pulse1_offset_ns_ + std::llround(pulse1);
    return event;
  }

  bool paced() const override { return options_.pacing == Pacing::real_time; }

 private:
  double draw() { return options_.jitter_ns > 0.0 ? options_.jitter_ns * normal_(rng_) : 0.0; }

  SimulatedTriggerOptions options_;
  std::int64_t period_ns_ = 0;
  double rate_hz_ = 1.0;
  std::int64_t dt_ns_ = 0;
  std::int64_t pulse1_offset_ns_ = 0;
  std::int64_t origin_ns_ = 0;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace

DeviceCapabilities simulated_capabilities(const SimulatedTriggerOptions& options) {
  DeviceCapabilities caps;
  caps.device = "simulated";
  caps.max_channels = options.max_channels;
  caps.resolution_ns = 1;
  caps.jitter_ns = std::llround(options.jitter_ns);
  caps.min_pulse_ns = 1;
  caps.drives_unwired_channels = true;
  return caps;
}

std::unique_ptr<DeviceBackend> make_simulated_backend(const SimulatedTriggerOptions& options) {
  return std::make_unique<SimulatedBackend>(options);
}

std::unique_ptr<TriggerDevice> make_simulated_device(const SimulatedTriggerOptions& options,
                                                     std::vector<LightSource> light_sources) {
  return std::make_unique<TriggerDevice>(make_simulated_backend(options), std::move(light_sources));
}

}  // namespace tomorig::trigger
