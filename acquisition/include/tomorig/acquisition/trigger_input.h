#pragma once
// What a camera needs to know about one trigger event. It mirrors the events of the trigger
// devices (trigger/) so they can be fed to cameras and to the assembler without acquisition
// depending on trigger/; the apps layer converts one into the other.
#include <cstdint>

namespace tomorig::acquisition {

struct TriggerInput {
  std::uint64_t index = 0;        // trigger event counter
  std::int64_t timestamp_ns = 0;  // time of the first pulse (exposure A), trigger clock
  std::int64_t dt_ns = 0;         // actual pulse separation A -> B of this event
};

}  // namespace tomorig::acquisition
