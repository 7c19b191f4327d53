#include <map>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "decode.h"

namespace tomorig::config::detail {
namespace {

constexpr Choice<TriggerBackend> kTriggerBackends[] = {
    {"gpio", TriggerBackend::gpio}, {"simulated", TriggerBackend::simulated}};

void decode_channel(TableReader& r, bool gpio, TriggerChannel& channel) {
  r.read("name", channel.name, Need::required, not_empty());
  r.read("role", channel.role, Need::required, one_of<std::string>({"light", "camera"}));
  // Only the GPIO backend drives real lines; the simulated device just names its channels.
  const Need wiring = gpio ? Need::required : Need::optional;
  r.read("chip", channel.chip, wiring, not_empty());
  r.read("line", channel.line, wiring, at_least(0));
  r.report_unknown_keys();
}

void decode_channels(TableReader& trigger, bool gpio, std::vector<TriggerChannel>& channels) {
  struct FirstUse {
    std::string path;
    int line;
  };
  std::map<std::string, FirstUse> names;
  std::map<std::pair<std::string, int>, FirstUse> wires;
  // A GPIO trigger without a channel would pulse nothing.
  for (auto& r : trigger.array_of_tables("channels", gpio ? Need::required : Need::optional)) {
    TriggerChannel channel;
    decode_channel(r, gpio, channel);
    if (!channel.name.empty()) {
      auto [it, inserted] = names.try_emplace(channel.name, FirstUse{r.path(), r.line_of("name")});
      if (!inserted)
        r.issue("name", fmt::format("\"{}\" is already used by {} (line {}); channel names must be unique",
                                    channel.name, it->second.path, it->second.line));
    }
    // Two channels on one GPIO line would fight over it.
    if (!channel.chip.empty() && channel.line >= 0) {
      auto [it, inserted] = wires.try_emplace({channel.chip, channel.line}, FirstUse{r.path(), r.line_of("line")});
      if (!inserted)
        r.issue("line", fmt::format("{} line {} is already used by {} (line {}); each channel needs its own line",
                                    channel.chip, channel.line, it->second.path, it->second.line));
    }
    channels.push_back(std::move(channel));
  }
}

}  // namespace

void decode_trigger(TableReader& root, TriggerConfig& t) {
  auto r = root.table("trigger");
  if (!r) return;
  // Required for the same reason as cameras[].backend: no silent fall-back to simulation.
  TriggerBackend backend{};
  const bool backend_known = r->read_choice("backend", backend, kTriggerBackends, Need::required);
  if (backend_known) t.backend = backend;

  const bool rate_ok = valid_or_absent(*r, "rate_hz", r->read("rate_hz", t.rate_hz, Need::optional, greater_than(0.0)));
  const bool dt_ok = valid_or_absent(*r, "dt_us", r->read("dt_us", t.dt_us, Need::optional, greater_than(0.0)));
  const bool width_ok =
      valid_or_absent(*r, "pulse_width_us", r->read("pulse_width_us", t.pulse_width_us, Need::optional, greater_than(0.0)));
  r->read("jitter_ns", t.jitter_ns, Need::optional, at_least(0.0));

  // Frame straddling: both pulses of an event fit inside one trigger period, and the first
  // pulse ends before the second starts. Detailed feasibility (camera interframing time,
  // laser limits) is the trigger module's job.
  if (rate_ok && dt_ok) {
    const double period_us = 1e6 / t.rate_hz;
    if (t.dt_us >= period_us)
      r->issue("dt_us", fmt::format("{} must be < the trigger period 1/rate_hz ({} us)", t.dt_us, period_us));
  }
  if (dt_ok && width_ok && t.pulse_width_us >= t.dt_us)
    r->issue("pulse_width_us", fmt::format("{} must be < dt_us ({})", t.pulse_width_us, t.dt_us));

  decode_channels(*r, backend_known && backend == TriggerBackend::gpio, t.channels);
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail
