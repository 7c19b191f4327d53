// Light-source limits, checked on the edges a device is about to output (not on the inputs the
// plan was built from), so a plan assembled by hand is judged by what it would really do.
#include "tomorig/trigger/safety_limits.h"

#include <algorithm>
#include <string>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/trigger/timing_plan.h"

namespace tomorig::trigger {
namespace {

constexpr ResolvedLimits kLed{2'000, 1e-3, 1000.0};
constexpr ResolvedLimits kLaser{20'000, 1e-3, 30.0};

std::string source_label(const LightSource& s, bool listed) {
  return listed ? fmt::format("light source '{}' ({})", s.name, to_string(s.kind))
                : fmt::format("light source '{}' (not in the device's light-source table: strictest defaults)", s.name);
}

std::string origin(const LightSource& s, bool configured) {
  return configured ? std::string("configured") : fmt::format("built-in {} default", to_string(s.kind));
}

}  // namespace

std::string_view to_string(LightSourceKind kind) {
  switch (kind) {
    case LightSourceKind::laser: return "laser";
    case LightSourceKind::led: return "led";
    case LightSourceKind::unknown: return "unknown";
  }
  return "?";
}

ResolvedLimits default_limits(LightSourceKind kind) {
  switch (kind) {
    case LightSourceKind::laser: return kLaser;
    case LightSourceKind::led: return kLed;
    case LightSourceKind::unknown: break;
  }
  return {std::min(kLed.max_pulse_width_ns, kLaser.max_pulse_width_ns), std::min(kLed.max_duty_cycle, kLaser.max_duty_cycle),
          std::min(kLed.max_rate_hz, kLaser.max_rate_hz)};
}

ResolvedLimits resolve_limits(const LightSource& source) {
  const ResolvedLimits d = default_limits(source.kind);
  return {source.limits.max_pulse_width_ns.value_or(d.max_pulse_width_ns),
          source.limits.max_duty_cycle.value_or(d.max_duty_cycle), source.limits.max_rate_hz.value_or(d.max_rate_hz)};
}

void enforce_safety_limits(const TimingPlan& plan, const std::vector<LightSource>& sources) {
  if (plan.period_ns <= 0)
    throw bad_input(fmt::format("refusing a trigger plan with period {} ns: the period must be > 0", plan.period_ns));
  for (const auto& ch : plan.channels) {
    for (const auto& p : ch.pulses)
      if (p.rise_ns < 0 || p.fall_ns <= p.rise_ns || p.fall_ns > plan.period_ns)
        throw bad_input(fmt::format("refusing a malformed trigger plan: channel '{}' has a pulse [{}, {}) that is empty "
                                    "or outside the period [0, {})",
                                    ch.spec.name, format_us(p.rise_ns), format_us(p.fall_ns), format_us(plan.period_ns)));
    const bool light = ch.spec.role == ChannelRole::light;
    if (!light && ch.spec.role != ChannelRole::flashlamp) continue;

    auto it = std::find_if(sources.begin(), sources.end(),
                           [&](const LightSource& s) { return s.name == ch.spec.light_source; });
    const bool listed = it != sources.end();
    LightSource source = listed ? *it : LightSource{};
    if (!listed) {
      source.name = ch.spec.light_source;
      source.kind = LightSourceKind::unknown;
      source.limits = {};
    }
    const ResolvedLimits limits = resolve_limits(source);
    const std::string who = source_label(source, listed);

    // The repetition rate of the events the source fires in: a laser head's rated rate. Two
    // pulses of an LED in one event are the duty cycle's concern.
    const double rate = ch.pulses.empty() ? 0.0 : 1e9 / static_cast<double>(plan.period_ns);
    if (rate > limits.max_rate_hz)
      throw bad_input(fmt::format(
          "safety limit max_rate_hz exceeded: {} would be fired at {:.6g} Hz on channel '{}', above its limit of "
          "{:.6g} Hz ({}); lower the rate",
          who, rate, ch.spec.name, limits.max_rate_hz, origin(source, source.limits.max_rate_hz.has_value())));
    if (!light) continue;  // a flash lamp's trigger width and duty are not its light

    std::int64_t high_ns = 0;
    for (const auto& p : ch.pulses) {
      high_ns += p.width_ns();
      if (p.width_ns() > limits.max_pulse_width_ns)
        throw bad_input(fmt::format(
            "safety limit max_pulse_width exceeded: {} would get a {} pulse on channel '{}', longer than its limit of {} "
            "({}); shorten the pulse",
            who, format_us(p.width_ns()), ch.spec.name, format_us(limits.max_pulse_width_ns),
            origin(source, source.limits.max_pulse_width_ns.has_value())));
    }
    const double duty = static_cast<double>(high_ns) / static_cast<double>(plan.period_ns);
    if (duty > limits.max_duty_cycle)
      throw bad_input(fmt::format(
          "safety limit max_duty_cycle exceeded: {} would be on {:.4g} % of the time on channel '{}', above its limit of "
          "{:.4g} % ({}); shorten the pulses or lower the rate",
          who, duty * 100.0, ch.spec.name, limits.max_duty_cycle * 100.0,
          origin(source, source.limits.max_duty_cycle.has_value())));
  }
}

}  // namespace tomorig::trigger
