#pragma once
// What a trigger device can time, and whether a plan asks for more.
#include <cstdint>
#include <string>
#include <vector>

#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger {

struct DeviceCapabilities {
  std::string device;               // "simulated", "gpio"
  int max_channels = 0;             // outputs it can drive
  std::int64_t resolution_ns = 1;   // smallest step between two edges it can place
  std::int64_t jitter_ns = 0;       // 1 sigma of an edge's time
  std::int64_t min_pulse_ns = 1;    // shortest high time of an output
  // Userspace GPIO: channels without a GPIO line are made by an external pulse generator,
  // which then also owns dt; without one, dt below the resolution is refused.
  bool drives_unwired_channels = true;
};

// Which channels the device outputs itself (the rest: an external pulse generator).
bool device_drives(const DeviceCapabilities& caps, const ChannelSpec& channel);

// Every way `plan` asks more than `caps` offers, one message each (empty: feasible). Each
// message names the quantity, its value and the device's bound.
std::vector<std::string> capability_problems(const TimingPlan& plan, const DeviceCapabilities& caps);

// Throws tomorig::Error (bad_input) listing capability_problems(), if any.
void require_capabilities(const TimingPlan& plan, const DeviceCapabilities& caps);

}  // namespace tomorig::trigger
