#include "tomorig/trigger/plan_diagram.h"

#include <algorithm>
#include <set>

#include <fmt/format.h>

namespace tomorig::trigger {
namespace {

constexpr std::size_t kColumn = 12;  // characters per time step; fits "100000.000"

std::string plain_us(std::int64_t ns) {
  std::string s = format_us(ns);
  return s.substr(0, s.size() - 3);  // without " us"
}

bool high_at(const std::vector<Pulse>& pulses, std::int64_t t) {
  return std::any_of(pulses.begin(), pulses.end(), [t](const Pulse& p) { return p.rise_ns <= t && t < p.fall_ns; });
}

// One row: '=' high, '_' low, '|' where the level changes.
std::string waveform(const std::vector<Pulse>& pulses, const std::vector<std::int64_t>& times) {
  std::string row;
  bool previous = false;
  for (std::size_t i = 0; i + 1 < times.size(); ++i) {
    const bool level = high_at(pulses, times[i]);
    const char fill = level ? '=' : '_';
    row += (i > 0 && level != previous) || (i == 0 && level) ? '|' : fill;
    row += std::string(kColumn - 1, fill);
    previous = level;
  }
  row += previous ? '|' : '_';
  return row;
}

}  // namespace

std::string timing_diagram(const TimingPlan& plan, const DeviceCapabilities& device) {
  std::string out;
  out += fmt::format("trigger plan: {:.6g} Hz (period {}), dt {} (pulse centre to centre), straddle margin +/- {}\n",
                     plan.rate_hz, format_us(plan.period_ns), format_us(plan.dt_ns),
                     format_us(plan.straddle_margin_ns));
  if (plan.camera.mode == FrameMode::two_triggers)
    out += fmt::format("camera: single-frame, two triggers: exposure {} per frame, readout {}, B - A {}\n",
                       format_us(plan.camera.exposure_a_ns), format_us(plan.camera.readout_ns),
                       format_us(plan.frame_separation_ns()));
  else
    out += fmt::format("camera: exposure A {}, interframe {}, exposure B {}\n", format_us(plan.camera.exposure_a_ns),
                       format_us(plan.camera.interframe_ns), format_us(plan.camera.exposure_b_ns));
  out += fmt::format("device: {} ({} channels, resolution {}, jitter {}, minimum pulse {})\n", device.device,
                     device.max_channels, format_us(device.resolution_ns), format_us(device.jitter_ns),
                     format_us(device.min_pulse_ns));

  std::set<std::int64_t> edge_set{0, plan.period_ns};
  for (const auto& ch : plan.channels)
    for (const auto& p : ch.pulses) edge_set.insert({p.rise_ns, p.fall_ns});
  for (const Pulse& p : {plan.frame_a, plan.frame_b, plan.light_pulse_1, plan.light_pulse_2})
    edge_set.insert({p.rise_ns, p.fall_ns});
  const std::vector<std::int64_t> times(edge_set.begin(), edge_set.end());

  std::size_t name_width = 10;
  for (const auto& ch : plan.channels) name_width = std::max(name_width, ch.spec.name.size() + 1);
  const std::size_t label = name_width + 16;

  out += "\ntiming diagram (us from the period start; one column per edge time, not to scale):\n";
  std::string axis(label, ' ');
  for (std::int64_t t : times) axis += fmt::format("{:<{}}", plain_us(t), kColumn);
  while (!axis.empty() && axis.back() == ' ') axis.pop_back();
  out += axis + "\n";
  for (const auto& ch : plan.channels) {
    const std::string role = fmt::format("{}{}", to_string(ch.spec.role), device_drives(device, ch.spec) ? "" : "*");
    out += fmt::format("{:<{}}{:<16}{}\n", ch.spec.name, name_width, role, waveform(ch.pulses, times));
  }
  out += fmt::format("{:<{}}{:<16}{}\n", "frame A", name_width, "(exposure)", waveform({plan.frame_a}, times));
  out += fmt::format("{:<{}}{:<16}{}\n", "frame B", name_width, "(exposure)", waveform({plan.frame_b}, times));
  out += fmt::format("{:<{}}{:<16}{}\n", "pulse 1", name_width, "(light)", waveform({plan.light_pulse_1}, times));
  out += fmt::format("{:<{}}{:<16}{}\n", "pulse 2", name_width, "(light)", waveform({plan.light_pulse_2}, times));
  if (plan.has_pulse_generator()) out += "(* made by the external pulse generator)\n";

  out += "\nedges (us from the period start, rise-fall):\n";
  for (const auto& ch : plan.channels) {
    std::string detail;
    if (!ch.spec.light_source.empty()) {
      const LightSource* s = plan.find_light_source(ch.spec.light_source);
      detail = fmt::format("source {} ({}), pulses {}, ", ch.spec.light_source,
                           s ? to_string(s->kind) : std::string_view("?"), to_string(ch.spec.pulses));
    }
    std::string edges;
    for (const auto& p : ch.pulses) edges += fmt::format("{}{}-{}", edges.empty() ? "" : ", ", plain_us(p.rise_ns),
                                                         plain_us(p.fall_ns));
    out += fmt::format("  {:<{}}{:<16}{}delay {}: {}\n", ch.spec.name, name_width, to_string(ch.spec.role), detail,
                       format_us(ch.spec.delay_ns), edges);
  }
  out += fmt::format("  frame A open {}-{}, frame B open {}-{}, pulse 1 {}-{}, pulse 2 {}-{}\n",
                     plain_us(plan.frame_a.rise_ns), plain_us(plan.frame_a.fall_ns), plain_us(plan.frame_b.rise_ns),
                     plain_us(plan.frame_b.fall_ns), plain_us(plan.light_pulse_1.rise_ns),
                     plain_us(plan.light_pulse_1.fall_ns), plain_us(plan.light_pulse_2.rise_ns),
                     plain_us(plan.light_pulse_2.fall_ns));
  return out;
}

}  // namespace tomorig::trigger
