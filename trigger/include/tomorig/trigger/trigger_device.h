#pragma once
// One interface for every trigger device: arm(plan), start(n or continuous), stop(), and a
// thread-safe queue of timestamped events. TriggerDevice is the only way a plan reaches an
// output: arm() enforces the light-source safety limits and the device's capabilities before
// the backend (simulated, gpio) ever sees the plan.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <stop_token>
#include <vector>

#include "tomorig/trigger/capabilities.h"
#include "tomorig/trigger/safety_limits.h"
#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger {

struct TriggerEvent {
  std::uint64_t index = 0;         // 0, 1, 2, ... within a run
  std::int64_t timestamp_ns = 0;   // start of the event's period, since start()
  std::int64_t dt_ns = 0;          // actual separation of the two light pulses (with jitter)
  std::int64_t pulse1_ns = 0;      // centre of light pulse 1 (exposure A), since start()
};

// What a device backend does; TriggerDevice adds safety, threading and the event queue.
class DeviceBackend {
 public:
  virtual ~DeviceBackend() = default;
  virtual DeviceCapabilities capabilities() const = 0;
  // Claims outputs for `plan`, which has passed the safety and capability checks.
  virtual void arm(const TimingPlan& plan) = 0;
  virtual void begin() {}  // a run starts: the time origin of event timestamps is now
  // Makes event k happen (waiting for its time if paced) and describes it; nullopt if `stop`
  // was requested meanwhile.
  virtual std::optional<TriggerEvent> fire(std::uint64_t k, std::stop_token stop) = 0;
  virtual void end() {}  // the run is over: outputs low
  // true: events happen in real time whether or not anyone reads them, so a full queue drops
  // (and counts) events; false: the next event waits until the consumer has taken one.
  virtual bool paced() const = 0;
};

class TriggerDevice {
 public:
  // `light_sources` is the device's safety table: limits are taken from here, never from
  // the plan. `queue_capacity` events are buffered for the consumer.
  TriggerDevice(std::unique_ptr<DeviceBackend> backend, std::vector<LightSource> light_sources,
                std::size_t queue_capacity = 256);
  ~TriggerDevice();  // stops a running device
  TriggerDevice(const TriggerDevice&) = delete;
  TriggerDevice& operator=(const TriggerDevice&) = delete;

  DeviceCapabilities capabilities() const;

  // Throws tomorig::Error (bad_input) naming the limit, the light source and the value when a
  // safety limit is exceeded, or listing what the device cannot time. Not while running.
  void arm(const TimingPlan& plan);
  bool armed() const;

  // Starts firing: `events` of them, or until stop() when nullopt. Needs arm() first.
  void start(std::optional<std::uint64_t> events);
  // Stops firing and waits for the worker; events already queued stay readable.
  void stop();

  // Blocks until an event is available (returned) or the run is over and every event has
  // been taken (nullopt). Rethrows an error the device hit while running.
  std::optional<TriggerEvent> next_event();
  // As next_event(), but also returns nullopt after `timeout` without an event.
  std::optional<TriggerEvent> next_event_for(std::chrono::nanoseconds timeout);

  // Events a paced device fired while the queue was full (the consumer lagged).
  std::uint64_t dropped_events() const;
  // Those events themselves (index, time, Δt), each returned once, oldest first; a consumer
  // that never calls this keeps at most 65536 of them.
  std::vector<TriggerEvent> take_dropped_events();
  // Events fired and waiting for the consumer; a paced device drops once this reaches
  // queue_capacity(), so it is the consumer's lag behind the trigger.
  std::size_t queued_events() const;
  std::size_t queue_capacity() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomorig::trigger
