// [[trigger.light_sources]]: what the trigger fires light with, and the safety limits that the
// trigger device enforces for it. Limits left out take the trigger module's defaults for the
// kind; a configured limit is bounded so that no entry can switch a limit off.
#include <map>
#include <string>

#include <fmt/format.h>

#include "decode.h"
#include "duration_rules.h"

namespace tomorig::config::detail {
namespace {

// Ceilings of configured safety limits (docs/configuration.md, "Light sources"):
//  - a pulse longer than 1 ms is continuous illumination, not a pulse a limit protects;
//  - a duty cycle is a fraction of the period: (0, 1];
//  - 100 kHz is above every pulsed PIV source (high-speed lasers and LEDs run at <= tens of kHz).
constexpr double kMaxPulseWidthCeilingUs = 1000.0;
constexpr double kMaxRateCeilingHz = 100'000.0;

// Reads an optional limit; `out` stays unset unless the value is present and allowed.
void read_limit(TableReader& r, std::string_view key, std::optional<double>& out, const Rule<double>& rule) {
  double value = 0.0;
  if (r.read(key, value, Need::optional, rule)) out = value;
}

void decode_light_source(TableReader& r, const TriggerConfig& t, bool dt_ok, LightSourceConfig& s) {
  r.read("name", s.name, Need::required, not_empty());
  // Optional: a source whose kind nobody stated gets the strictest limits of every kind.
  r.read_choice("kind", s.kind);
  s.pulse_width_us = t.pulse_width_us;
  const bool width_ok = r.read("pulse_width_us", s.pulse_width_us, Need::optional, positive_duration_us());
  // Two pulses of one source dt apart must not merge (as trigger.pulse_width_us).
  if (width_ok && dt_ok && s.pulse_width_us >= t.dt_us)
    r.issue("pulse_width_us", fmt::format("{} must be < trigger.dt_us ({})", s.pulse_width_us, t.dt_us));

  if (r.read("flashlamp_lead_us", s.flashlamp_lead_us, Need::optional, non_negative_time_us()) && s.kind != LightSourceKind::laser) {
    r.issue("flashlamp_lead_us",
            fmt::format("only lasers have a flash lamp, but this source is {}: set kind = \"laser\" or remove the key",
                        s.kind == LightSourceKind::unknown ? std::string("of no stated kind")
                                                          : fmt::format("kind = \"{}\"", to_string(s.kind))));
    s.flashlamp_lead_us = 0.0;
  }

  read_limit(r, "max_pulse_width_us", s.max_pulse_width_us,
             in_range_because(kTimeStepUs, true, kMaxPulseWidthCeilingUs,
                              "longer than 1 ms is continuous light, not a pulse a limit can protect"));
  read_limit(r, "max_duty_cycle", s.max_duty_cycle,
             in_range_because(0.0, false, 1.0, "a fraction of the period: 1 is always on"));
  read_limit(r, "max_rate_hz", s.max_rate_hz,
             in_range_because(0.0, false, kMaxRateCeilingHz, "above every pulsed PIV light source"));
  r.report_unknown_keys();
}

}  // namespace

void decode_light_sources(TableReader& trigger, const TriggerConfig& t, bool dt_ok,
                          std::vector<LightSourceConfig>& sources) {
  struct FirstUse {
    std::string path;
    int line;
  };
  std::map<std::string, FirstUse> names;
  for (auto& r : trigger.array_of_tables("light_sources", Need::optional)) {
    LightSourceConfig source;
    decode_light_source(r, t, dt_ok, source);
    if (!source.name.empty()) {
      auto [it, inserted] = names.try_emplace(source.name, FirstUse{r.path(), r.line_of("name")});
      if (!inserted)
        r.issue("name", fmt::format("\"{}\" is already used by {} (line {}); light source names must be unique",
                                    source.name, it->second.path, it->second.line));
    }
    sources.push_back(std::move(source));
  }
}

}  // namespace tomorig::config::detail
