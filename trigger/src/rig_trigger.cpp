#include "tomorig/trigger/rig_trigger.h"

#include <cmath>

namespace tomorig::trigger {
namespace {

std::int64_t us_to_ns(double us) { return std::llround(us * 1000.0); }

}  // namespace

DeviceCapabilities RigTrigger::capabilities() const {
  return backend == config::TriggerBackend::gpio ? gpio_capabilities(gpio) : simulated_capabilities(simulated);
}

RigTrigger rig_trigger(const config::RigConfig& rig) {
  const config::TriggerConfig& t = rig.trigger;
  RigTrigger out;
  out.backend = t.backend;
  out.inputs.rate_hz = t.rate_hz;
  out.inputs.dt_ns = us_to_ns(t.dt_us);
  out.simulated.jitter_ns = t.jitter_ns;
  if (rig.simulation) out.simulated.seed = rig.simulation->seed;

  const bool gpio = t.backend == config::TriggerBackend::gpio;
  // A GPIO output cannot be shorter than the device resolution; hardware trigger inputs take
  // the 10 µs default.
  const std::int64_t trigger_width = gpio ? out.gpio.resolution_ns : 0;
  auto add_light = [&](const std::string& name, const std::string& chip, int line) {
    LightSource source;
    source.name = name;
    source.kind = LightSourceKind::unknown;
    source.pulse_width_ns = us_to_ns(t.pulse_width_us);
    out.inputs.light_sources.push_back(source);
    ChannelSpec c;
    c.name = name;
    c.role = ChannelRole::light;
    c.light_source = name;
    c.pulses = PulseSelect::both;
    c.chip = chip;
    c.line = line;
    out.inputs.channels.push_back(c);
  };
  auto add_camera = [&](const std::string& name, const std::string& chip, int line) {
    ChannelSpec c;
    c.name = name;
    c.role = ChannelRole::camera;
    c.width_ns = trigger_width;
    c.chip = chip;
    c.line = line;
    out.inputs.channels.push_back(c);
  };
  for (const auto& ch : t.channels) {
    if (ch.role == "light")
      add_light(ch.name, ch.chip, ch.line);
    else
      add_camera(ch.name, ch.chip, ch.line);
  }
  if (t.channels.empty() && !gpio) {
    add_camera("cameras", "", -1);
    add_light("light", "", -1);
  }
  return out;
}

TimingPlan plan_and_check(const RigTrigger& trigger) {
  TimingPlan plan = plan_timing(trigger.inputs);
  enforce_safety_limits(plan, trigger.inputs.light_sources);
  require_capabilities(plan, trigger.capabilities());
  return plan;
}

std::unique_ptr<TriggerDevice> make_trigger_device(const RigTrigger& trigger, Pacing pacing) {
  if (trigger.backend == config::TriggerBackend::gpio) return make_gpio_device(trigger.gpio, trigger.inputs.light_sources);
  SimulatedTriggerOptions options = trigger.simulated;
  options.pacing = pacing;
  return make_simulated_device(options, trigger.inputs.light_sources);
}

}  // namespace tomorig::trigger
