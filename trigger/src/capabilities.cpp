#include "tomorig/trigger/capabilities.h"

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::trigger {
namespace {

// Pulses must keep inside their frames despite jitter; 3 sigma keeps >99.7 % of events good.
constexpr int kJitterSigmas = 3;

}  // namespace

bool device_drives(const DeviceCapabilities& caps, const ChannelSpec& channel) {
  return caps.drives_unwired_channels || channel.wired();
}

std::vector<std::string> capability_problems(const TimingPlan& plan, const DeviceCapabilities& caps) {
  std::vector<std::string> out;
  const std::string dev = caps.device;

  int driven = 0;
  bool drives_timing_critical = false;
  for (const auto& ch : plan.channels) {
    if (!device_drives(caps, ch.spec)) {
      if (ch.spec.role == ChannelRole::pulse_generator)
        out.push_back(fmt::format("pulse_generator channel '{}' has no {} output (chip and line): nothing would "
                                  "trigger the generator; wire it",
                                  ch.spec.name, dev));
      else if (!plan.has_pulse_generator())
        out.push_back(fmt::format("channel '{}' has no {} output (chip and line) and no pulse_generator channel is "
                                  "configured to make it; wire it or add an external pulse generator",
                                  ch.spec.name, dev));
      continue;
    }
    ++driven;
    drives_timing_critical = drives_timing_critical || ch.spec.role == ChannelRole::camera ||
                             ch.spec.role == ChannelRole::light;
    for (const auto& p : ch.pulses) {
      if (p.width_ns() < caps.min_pulse_ns) {
        out.push_back(fmt::format("channel '{}': pulse width {} is below the {} device's minimum pulse of {}",
                                  ch.spec.name, format_us(p.width_ns()), dev, format_us(caps.min_pulse_ns)));
        break;
      }
      if (p.width_ns() < caps.resolution_ns) {
        out.push_back(fmt::format("channel '{}': pulse width {} is below the {} device's time resolution of {}",
                                  ch.spec.name, format_us(p.width_ns()), dev, format_us(caps.resolution_ns)));
        break;
      }
    }
  }
  if (driven > caps.max_channels)
    out.push_back(fmt::format("the plan needs {} output channels, the {} device has {}", driven, dev, caps.max_channels));
  if (plan.dt_ns < caps.resolution_ns && !plan.has_pulse_generator())
    out.push_back(fmt::format("dt {} is below the {} device's time resolution of {}; configure an external "
                              "pulse_generator channel to make the pulses, or raise dt to >= {}",
                              format_us(plan.dt_ns), dev, format_us(caps.resolution_ns), format_us(caps.resolution_ns)));
  const std::int64_t needed = kJitterSigmas * caps.jitter_ns;
  if (drives_timing_critical && plan.straddle_margin_ns < needed)
    out.push_back(fmt::format("the straddle margin {} (how far the pulses may move and stay inside frames A and B) "
                              "is below {} x the {} device's jitter of {} = {}; lengthen exposure A or use a "
                              "device with less jitter",
                              format_us(plan.straddle_margin_ns), kJitterSigmas, dev, format_us(caps.jitter_ns),
                              format_us(needed)));
  return out;
}

void require_capabilities(const TimingPlan& plan, const DeviceCapabilities& caps) {
  const auto problems = capability_problems(plan, caps);
  if (problems.empty()) return;
  std::string message = fmt::format("the trigger plan exceeds what the {} device can do:", caps.device);
  for (const auto& p : problems) message += "\n  " + p;
  throw bad_input(message);
}

}  // namespace tomorig::trigger
