#pragma once
// The gpio trigger device: output lines by chip and offset through libgpiod 1.6.
//
// Userspace GPIO cannot time microsecond pulses. Setting a line is a syscall taking a few µs,
// but the thread making it can be preempted by the scheduler for milliseconds on a kernel
// without PREEMPT_RT, so an edge is only trustworthy to about 1 ms. The gpio device therefore
// drives camera triggers, gates and the trigger input of an external pulse generator at ms
// scale, and refuses a plan whose dt or pulses are below its resolution unless a
// pulse_generator channel makes them (channels without chip/line are the generator's).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/trigger/clock.h"
#include "tomorig/trigger/trigger_device.h"

namespace tomorig::trigger {

struct GpioLineId {
  std::string chip;  // e.g. "gpiochip0"
  unsigned offset = 0;
};

// The few GPIO operations the device needs; libgpiod in production, a fake in tests.
class GpioLines {
 public:
  virtual ~GpioLines() = default;
  // Claims `lines` as outputs, all low, for `consumer` (releasing any earlier claim). Throws
  // tomorig::Error naming the chip (and line) that cannot be opened or claimed.
  virtual void request(const std::vector<GpioLineId>& lines, const std::string& consumer) = 0;
  virtual void set(std::size_t index, bool high) = 0;  // index into the requested lines
  virtual void release() = 0;                          // frees the lines
};

std::unique_ptr<GpioLines> make_libgpiod_lines();

struct GpioTriggerOptions {
  std::int64_t resolution_ns = 1'000'000;  // 1 ms: scheduling latency of a userspace thread
  std::int64_t jitter_ns = 250'000;        // 1 sigma of an edge on a loaded, non-RT kernel
  int max_lines = 64;                      // libgpiod's limit for one request
  std::string consumer = "tomorig";        // shown by gpioinfo for the claimed lines
  std::shared_ptr<Clock> clock;            // null: steady_clock()
};

DeviceCapabilities gpio_capabilities(const GpioTriggerOptions& options);

std::unique_ptr<DeviceBackend> make_gpio_backend(std::unique_ptr<GpioLines> lines, const GpioTriggerOptions& options);

// A TriggerDevice on real GPIO (libgpiod) with `light_sources` as its safety table.
std::unique_ptr<TriggerDevice> make_gpio_device(const GpioTriggerOptions& options,
                                                std::vector<LightSource> light_sources);

}  // namespace tomorig::trigger
