#pragma once
// The simulated trigger device: exact timestamps (event k at k / rate) plus Gaussian jitter
// from a seeded RNG, so a run is reproducible. It drives the simulated cameras, which render
// each event with its actual dt: a dt error shows up as a displacement error.
#include <cstdint>
#include <memory>

#include "tomorig/trigger/clock.h"
#include "tomorig/trigger/trigger_device.h"

namespace tomorig::trigger {

enum class Pacing : std::uint8_t {
  as_fast_as_consumed,  // no waiting: the next event is made when the consumer took the last
  real_time,            // event k happens at start + k / rate on the clock (tomorig run)
};

struct SimulatedTriggerOptions {
  double jitter_ns = 0.0;   // 1 sigma of every edge (trigger and each light pulse), >= 0
  std::uint64_t seed = 1;   // same seed, same jitter
  Pacing pacing = Pacing::as_fast_as_consumed;
  std::shared_ptr<Clock> clock;  // real_time pacing; null: steady_clock()
  int max_channels = 64;
};

// Resolution 1 ns, minimum pulse 1 ns, jitter as configured.
DeviceCapabilities simulated_capabilities(const SimulatedTriggerOptions& options);

std::unique_ptr<DeviceBackend> make_simulated_backend(const SimulatedTriggerOptions& options);

// A TriggerDevice with the simulated backend and `light_sources` as its safety table.
std::unique_ptr<TriggerDevice> make_simulated_device(const SimulatedTriggerOptions& options,
                                                     std::vector<LightSource> light_sources);

}  // namespace tomorig::trigger
