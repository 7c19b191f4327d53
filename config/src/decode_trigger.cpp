#include <fmt/format.h>

#include "decode.h"
#include "duration_rules.h"

namespace tomorig::config::detail {
namespace {

// Userspace GPIO edges wait for the scheduler: even a PREEMPT_RT kernel has worst-case
// wake-up latencies of tens of µs, so a finer resolution would be a promise the gpio device
// cannot keep (it would then accept µs pulses it cannot time).
constexpr double kFinestGpioResolutionUs = 100.0;

}  // namespace

void decode_camera_timing(TableReader& trigger, CameraTimingConfig& camera) {
  auto r = trigger.table("camera");
  if (!r) return;
  r->read("exposure_a_us", camera.exposure_a_us, Need::optional, positive_duration_us());
  r->read("interframe_us", camera.interframe_us, Need::optional, non_negative_time_us());
  r->read("exposure_b_us", camera.exposure_b_us, Need::optional, positive_duration_us());
  r->read("readout_us", camera.readout_us, Need::optional, positive_duration_us());
  double tolerance = 0.0;
  if (r->read("frame_time_tolerance_us", tolerance, Need::optional, positive_duration_us()))
    camera.frame_time_tolerance_us = tolerance;
  r->report_unknown_keys();
}

void decode_trigger(TableReader& root, TriggerConfig& t) {
  auto r = root.table("trigger");
  if (!r) return;
  // Required for the same reason as cameras[].backend: no silent fall-back to simulation.
  TriggerBackend backend{};
  const bool backend_known = r->read_choice("backend", backend, Need::required);
  if (backend_known) t.backend = backend;

  const Rule<double> rate_rule{[](const double& v) -> std::optional<std::string> {
    if (!(v > 0.0)) return std::string("must be > 0");
    if (v >= kMinRateHz && v <= kMaxRateHz) return std::nullopt;
    return fmt::format("must be in [{:g}, {:g}] (a trigger period of 1 us to 1000 s)", kMinRateHz, kMaxRateHz);
  }};
  const bool rate_ok = valid_or_absent(*r, "rate_hz", r->read("rate_hz", t.rate_hz, Need::optional, rate_rule));
  const bool dt_ok =
      valid_or_absent(*r, "dt_us", r->read("dt_us", t.dt_us, Need::optional, bounded_time_us(greater_than(0.0))));
  const bool width_ok = valid_or_absent(
      *r, "pulse_width_us", r->read("pulse_width_us", t.pulse_width_us, Need::optional, bounded_time_us(greater_than(0.0))));
  r->read("jitter_ns", t.jitter_ns, Need::optional,
          and_at_most(at_least(0.0), kMaxDurationUs * 1e3, "1000 s, the longest time a rig file may give"));
  r->read("gpio_resolution_us", t.gpio_resolution_us, Need::optional,
          Rule<double>{[](const double& v) -> std::optional<std::string> {
            if (v >= kFinestGpioResolutionUs && v <= kMaxDurationUs) return std::nullopt;
            if (v > kMaxDurationUs) return fmt::format("must be <= {:g} (1000 s)", kMaxDurationUs);
            return fmt::format("must be >= {} (a userspace GPIO edge cannot be timed finer, even on PREEMPT_RT; "
                               "add a pulse_generator channel for us timing)",
                               kFinestGpioResolutionUs);
          }});

  // Frame straddling: both pulses of an event fit inside one trigger period, and the first
  // pulse ends before the second starts. Detailed feasibility (camera interframe time, safety
  // limits) is the trigger module's job (`tomorig trigger plan`).
  if (rate_ok && dt_ok) {
    const double period_us = 1e6 / t.rate_hz;
    if (t.dt_us >= period_us)
      r->issue("dt_us", fmt::format("{} must be < the trigger period 1/rate_hz ({} us)", t.dt_us, period_us));
  }
  if (dt_ok && width_ok && t.pulse_width_us >= t.dt_us)
    r->issue("pulse_width_us", fmt::format("{} must be < dt_us ({})", t.pulse_width_us, t.dt_us));

  decode_camera_timing(*r, t.camera);
  decode_light_sources(*r, t, dt_ok, t.light_sources);
  decode_trigger_channels(*r, backend_known && backend == TriggerBackend::gpio, t.light_sources, t.channels);
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail
