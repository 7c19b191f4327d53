// The rig config's [trigger] table as timing inputs, light-source safety table and device.
#include "tomorig/trigger/rig_trigger.h"

#include <algorithm>
#include <cmath>

namespace tomorig::trigger {
namespace {

std::int64_t us_to_ns(double us) { return std::llround(us * 1000.0); }

LightSource light_source(const config::LightSourceConfig& s) {
  LightSource out;
  out.name = s.name;
  out.kind = s.kind;
  out.pulse_width_ns = us_to_ns(s.pulse_width_us);
  out.flashlamp_lead_ns = us_to_ns(s.flashlamp_lead_us);
  if (s.max_pulse_width_us) out.limits.max_pulse_width_ns = us_to_ns(*s.max_pulse_width_us);
  out.limits.max_duty_cycle = s.max_duty_cycle;
  out.limits.max_rate_hz = s.max_rate_hz;
  return out;
}

// A light channel of a rig without [[trigger.light_sources]]: its own source, kind not stated.
LightSource own_light_source(const std::string& channel, double pulse_width_us) {
  LightSource out;
  out.name = channel;
  out.kind = LightSourceKind::unknown;
  out.pulse_width_ns = us_to_ns(pulse_width_us);
  return out;
}

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
  out.inputs.camera.exposure_a_ns = us_to_ns(t.camera.exposure_a_us);
  out.inputs.camera.interframe_ns = us_to_ns(t.camera.interframe_us);
  out.inputs.camera.exposure_b_ns = us_to_ns(t.camera.exposure_b_us);
  out.inputs.camera.readout_ns = us_to_ns(t.camera.readout_us);
  // The triggered cameras share one frame mode (the config checks it); free-running cameras
  // take no trigger and have no place in the plan.
  for (const auto& cam : rig.cameras)
    if (cam.frame_mode == config::FrameMode::two_triggers) out.inputs.camera.mode = FrameMode::two_triggers;
  out.simulated.jitter_ns = t.jitter_ns;
  if (rig.simulation) out.simulated.seed = rig.simulation->seed;
  out.gpio.resolution_ns = us_to_ns(t.gpio_resolution_us);
  for (const auto& s : t.light_sources) out.inputs.light_sources.push_back(light_source(s));

  const bool gpio = t.backend == config::TriggerBackend::gpio;
  for (const auto& ch : t.channels) {
    ChannelSpec c;
    c.name = ch.name;
    c.role = ch.role;
    c.chip = ch.chip;
    c.line = ch.line;
    c.delay_ns = us_to_ns(ch.delay_us);
    if (c.role == ChannelRole::light || c.role == ChannelRole::flashlamp) {
      c.pulses = ch.pulses;
      c.light_source = ch.light_source.empty() ? ch.name : ch.light_source;
      if (ch.light_source.empty()) out.inputs.light_sources.push_back(own_light_source(ch.name, t.pulse_width_us));
    }
    if (ch.width_us) {
      c.width_ns = us_to_ns(*ch.width_us);
    } else if (gpio && c.wired() && c.role != ChannelRole::light) {
      // A GPIO output cannot be shorter than the device resolution; trigger inputs made by a
      // pulse generator take the trigger module's 10 µs default, light its source's width.
      c.width_ns = out.gpio.resolution_ns;
    }
    out.inputs.channels.push_back(c);
  }
  if (t.channels.empty() && !gpio) {
    ChannelSpec camera;
    camera.name = "cameras";
    camera.role = ChannelRole::camera;
    out.inputs.channels.push_back(camera);
    ChannelSpec light;
    light.name = "light";
    light.role = ChannelRole::light;
    light.light_source = "light";
    light.pulses = PulseSelect::both;
    out.inputs.channels.push_back(light);
    // The stand-in channel fires the one declared source (or one named "light"); otherwise
    // it is its own source of no stated kind.
    auto& source = out.inputs.channels.back().light_source;
    const bool named_light = std::any_of(t.light_sources.begin(), t.light_sources.end(),
                                         [](const config::LightSourceConfig& s) { return s.name == "light"; });
    if (t.light_sources.size() == 1 && !named_light)
      source = t.light_sources.front().name;
    else if (!named_light)
      out.inputs.light_sources.push_back(own_light_source("light", t.pulse_width_us));
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
