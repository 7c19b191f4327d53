// Light-source limits, checked on the edges a device is about to output (not on the inputs the
// plan was built from), so a plan assembled by hand is judged by what it would really do.
#include "tomorig/trigger/safety_limits.h"

#include <algorithm>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

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


// Every channel that drives one light source, and the pulses that make its light.
struct SourceUse {
  std::string name;
  bool fires = false;                       // some light or flash-lamp channel pulses it
  std::vector<std::string> all_channels;    // light and flash-lamp channels, plan order
  std::vector<std::string> light_channels;  // light channels only
  std::vector<Pulse> light_pulses;          // every light channel's pulses, unmerged
};

std::vector<SourceUse> group_by_source(const TimingPlan& plan) {
  std::vector<SourceUse> uses;
  for (const auto& ch : plan.channels) {
    const bool light = ch.spec.role == ChannelRole::light;
    if (!light && ch.spec.role != ChannelRole::flashlamp) continue;
    auto it = std::find_if(uses.begin(), uses.end(), [&](const SourceUse& u) { return u.name == ch.spec.light_source; });
    if (it == uses.end()) {
      uses.push_back({ch.spec.light_source, false, {}, {}, {}});
      it = std::prev(uses.end());
    }
    it->fires = it->fires || !ch.pulses.empty();
    it->all_channels.push_back(ch.spec.name);
    if (!light) continue;
    it->light_channels.push_back(ch.spec.name);
    it->light_pulses.insert(it->light_pulses.end(), ch.pulses.begin(), ch.pulses.end());
  }
  return uses;
}

// The intervals in which the source is on: the union of its channels' pulses, with pulses that
// overlap or touch merged into one (the LED sees one long pulse), including a pulse that ends at
// the period's end and one that starts at 0 (they touch across the period boundary). Pulses lie
// in [0, period], checked before.
std::vector<Pulse> light_on_intervals(std::vector<Pulse> pulses, std::int64_t period_ns) {
  std::sort(pulses.begin(), pulses.end(), [](const Pulse& a, const Pulse& b) { return a.rise_ns < b.rise_ns; });
  std::vector<Pulse> on;
  for (const Pulse& p : pulses) {
    if (!on.empty() && p.rise_ns <= on.back().fall_ns)
      on.back().fall_ns = std::max(on.back().fall_ns, p.fall_ns);
    else
      on.push_back(p);
  }
  if (on.size() > 1 && on.front().rise_ns == 0 && on.back().fall_ns == period_ns) {
    // One pulse across the boundary: its width is the two pieces together.
    on.front().rise_ns = on.back().rise_ns - period_ns;
    on.pop_back();
  }
  return on;
}

std::string channel_list(const std::vector<std::string>& names) {
  if (names.size() == 1) return fmt::format("channel '{}'", names.front());
  return fmt::format("channels '{}' together", fmt::join(names, "', '"));
}

}  // namespace

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
  for (const auto& ch : plan.channels)
    for (const auto& p : ch.pulses)
      if (p.rise_ns < 0 || p.fall_ns <= p.rise_ns || p.fall_ns > plan.period_ns)
        throw bad_input(fmt::format("refusing a malformed trigger plan: channel '{}' has a pulse [{}, {}) that is empty "
                                    "or outside the period [0, {})",
                                    ch.spec.name, format_us(p.rise_ns), format_us(p.fall_ns), format_us(plan.period_ns)));

  // Limits belong to a light source, not to a channel: an LED split over two channels (one
  // firing pulse 1, the other pulse 2) is still one LED, and its on-time is the union of every
  // channel's pulses.
  for (const SourceUse& use : group_by_source(plan)) {
    auto it = std::find_if(sources.begin(), sources.end(), [&](const LightSource& s) { return s.name == use.name; });
    const bool listed = it != sources.end();
    LightSource source = listed ? *it : LightSource{};
    if (!listed) {
      source.name = use.name;
      source.kind = LightSourceKind::unknown;
      source.limits = {};
    }
    const ResolvedLimits limits = resolve_limits(source);
    const std::string who = source_label(source, listed);
    const std::string channels = channel_list(use.all_channels);

    // The repetition rate of the events the source fires in: a laser head's rated rate. Two
    // pulses of an LED in one event are the duty cycle's concern.
    const double rate = use.fires ? 1e9 / static_cast<double>(plan.period_ns) : 0.0;
    if (rate > limits.max_rate_hz)
      throw bad_input(fmt::format(
          "safety limit max_rate_hz exceeded: {} would be fired at {:.6g} Hz on {}, above its limit of "
          "{:.6g} Hz ({}); lower the rate",
          who, rate, channels, limits.max_rate_hz, origin(source, source.limits.max_rate_hz.has_value())));
    if (use.light_pulses.empty()) continue;  // a flash lamp's trigger width and duty are not its light

    const std::string light_channels = channel_list(use.light_channels);
    const std::vector<Pulse> on = light_on_intervals(use.light_pulses, plan.period_ns);
    std::int64_t high_ns = 0;
    for (const Pulse& p : on) {
      high_ns += p.width_ns();
      if (p.width_ns() > limits.max_pulse_width_ns)
        throw bad_input(fmt::format(
            "safety limit max_pulse_width exceeded: {} would get a {} pulse on {}, longer than its limit of {} "
            "({}); shorten the pulse{}",
            who, format_us(p.width_ns()), light_channels, format_us(limits.max_pulse_width_ns),
            origin(source, source.limits.max_pulse_width_ns.has_value()),
            use.light_channels.size() > 1 ? " (pulses of its channels that overlap or touch are one pulse of the source)" : ""));
    }
    const double duty = static_cast<double>(high_ns) / static_cast<double>(plan.period_ns);
    if (duty > limits.max_duty_cycle)
      throw bad_input(fmt::format(
          "safety limit max_duty_cycle exceeded: {} would be on {:.4g} % of the time on {}, above its limit of "
          "{:.4g} % ({}); shorten the pulses or lower the rate",
          who, duty * 100.0, light_channels, limits.max_duty_cycle * 100.0,
          origin(source, source.limits.max_duty_cycle.has_value())));
  }
}

}  // namespace tomorig::trigger
