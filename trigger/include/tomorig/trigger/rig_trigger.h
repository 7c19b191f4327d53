#pragma once
// From the rig configuration to timing inputs and a device. Every input comes from the
// [trigger] table (docs/configuration.md): rate, dt, camera timing ([trigger.camera]), light
// sources with kinds and safety limits ([[trigger.light_sources]]), channel roles, delays and
// widths, GPIO wiring and resolution. Keys left out take the defaults of TimingInputs /
// default_limits() (docs/trigger.md lists them).
#include <memory>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/trigger/capabilities.h"
#include "tomorig/trigger/gpio_device.h"
#include "tomorig/trigger/simulated_device.h"
#include "tomorig/trigger/timing_plan.h"
#include "tomorig/trigger/trigger_device.h"

namespace tomorig::trigger {

struct RigTrigger {
  config::TriggerBackend backend = config::TriggerBackend::simulated;
  TimingInputs inputs;                  // light sources included: they are the safety table too
  SimulatedTriggerOptions simulated;    // backend == simulated
  GpioTriggerOptions gpio;              // backend == gpio
  DeviceCapabilities capabilities() const;
};

// Light sources carry their configured kind and limits (unset limits: the kind's built-in
// defaults; no kind: the strictest). A light channel of a rig without [[trigger.light_sources]]
// is its own source (named after the channel, kind unknown, width trigger.pulse_width_us).
// Wired channels of the gpio backend default to a width of the GPIO resolution. A simulated rig
// without channels gets one camera channel "cameras" and one light channel "light" (firing the
// one declared light source, if exactly one is declared).
RigTrigger rig_trigger(const config::RigConfig& rig);

// Plans and checks everything a device would check at arm(): timing, safety limits, device
// capabilities. Throws tomorig::Error (bad_input) with the reasons.
TimingPlan plan_and_check(const RigTrigger& trigger);

// The configured device, not yet armed. `pacing` applies to the simulated backend.
std::unique_ptr<TriggerDevice> make_trigger_device(const RigTrigger& trigger, Pacing pacing = Pacing::real_time);

}  // namespace tomorig::trigger
