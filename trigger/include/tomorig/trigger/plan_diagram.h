#pragma once
// The plan as plain text: a timing diagram (one row per channel, a column per edge time, so
// ns pulses and ms frames both stay visible) and the edge times in µs.
#include <string>

#include "tomorig/trigger/capabilities.h"
#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger {

std::string timing_diagram(const TimingPlan& plan, const DeviceCapabilities& device);

}  // namespace tomorig::trigger
