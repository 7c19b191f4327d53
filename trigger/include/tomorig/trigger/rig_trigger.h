#pragma once
// From the rig configuration to timing inputs and a device. The [trigger] table holds the
// rate, dt, one pulse width and the channels; what it does not (yet) hold - camera exposure
// and interframe time, light-source kinds and limits, channel delays - takes the defaults of
// TimingInputs / default_limits() (docs/trigger.md lists them).
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

// Each light channel becomes its own light source (named after the channel, kind unknown, so
// the strictest built-in limits apply) making both pulses; camera channels trigger cameras. A
// simulated rig without channels gets one camera channel "cameras" and one light channel "light".
RigTrigger rig_trigger(const config::RigConfig& rig);

// Plans and checks everything a device would check at arm(): timing, safety limits, device
// capabilities. Throws tomorig::Error (bad_input) with the reasons.
TimingPlan plan_and_check(const RigTrigger& trigger);

// The configured device, not yet armed. `pacing` applies to the simulated backend.
std::unique_ptr<TriggerDevice> make_trigger_device(const RigTrigger& trigger, Pacing pacing = Pacing::real_time);

}  // namespace tomorig::trigger
