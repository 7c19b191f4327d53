// [[trigger.channels]]: the outputs of the trigger, their role, the light source they fire,
// their timing and their GPIO wiring.
#include <algorithm>
#include <map>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "decode.h"
#include "duration_rules.h"

namespace tomorig::config::detail {
namespace {

struct FirstUse {
  std::string path;
  int line;
};

// What decoding one channel needs to know about the rest of [trigger].
struct ChannelContext {
  bool gpio = false;
  bool has_pulse_generator = false;  // some channel has role "pulse_generator"
  const std::vector<LightSourceConfig>* sources = nullptr;
};

std::string declared_names(const std::vector<LightSourceConfig>& sources) {
  std::vector<std::string> names;
  for (const auto& s : sources)
    if (!s.name.empty()) names.push_back(fmt::format("\"{}\"", s.name));
  return names.empty() ? std::string("none are declared") : fmt::format("declared: {}", fmt::join(names, ", "));
}

// `role_known`: the channel's role was read (else it was missing or invalid: already reported).
void decode_light_source_ref(TableReader& r, const ChannelContext& ctx, bool role_known, TriggerChannel& ch) {
  const auto& sources = *ctx.sources;
  const bool present = r.has("light_source");
  const bool read_ok = r.read("light_source", ch.light_source, Need::optional, not_empty());
  if (!role_known) return;
  if (!drives_light(ch.role)) {
    if (present)
      r.issue("light_source", fmt::format("only light and flashlamp channels fire a light source, and this channel's role "
                                          "is \"{}\": remove the key",
                                          to_string(ch.role)));
    ch.light_source.clear();
    return;
  }
  if (!present) {
    // Without declared sources a light channel is its own source (kind not stated: strictest
    // limits). A flash lamp must say which laser it pumps.
    if (ch.role == ChannelRole::flashlamp || !sources.empty())
      r.issue("light_source",
              fmt::format("required key is missing (expected a string naming a [[trigger.light_sources]] entry, {}){}",
                          declared_names(sources),
                          ch.role == ChannelRole::flashlamp ? ": a flashlamp channel fires the flash lamp of one laser" : ""));
    return;
  }
  if (!read_ok) return;
  auto it = std::find_if(sources.begin(), sources.end(),
                         [&](const LightSourceConfig& s) { return s.name == ch.light_source; });
  if (it == sources.end()) {
    r.issue("light_source", fmt::format("\"{}\" is not a declared light source ({}); add a [[trigger.light_sources]] "
                                        "entry with that name or use a declared one",
                                        ch.light_source, declared_names(sources)));
    return;
  }
  if (ch.role == ChannelRole::flashlamp && it->kind != LightSourceKind::laser) {
    const std::string kind = it->kind == LightSourceKind::unknown ? std::string("of no stated kind")
                                                                  : fmt::format("of kind \"{}\"", to_string(it->kind));
    r.issue("light_source", fmt::format("\"{}\" is {}, but a flashlamp channel fires the flash lamp of a laser: use a "
                                        "light source with kind = \"laser\"",
                                        ch.light_source, kind));
  }
}

void decode_timing_and_wiring(TableReader& r, const ChannelContext& ctx, bool role_known, TriggerChannel& ch) {
  const bool present = r.has("pulses");
  r.read_choice("pulses", ch.pulses);
  if (present && role_known && !drives_light(ch.role))
    r.issue("pulses", fmt::format("only light and flashlamp channels choose their pulses, and this channel's role is "
                                  "\"{}\": remove the key",
                                  to_string(ch.role)));
  r.read("delay_us", ch.delay_us, Need::optional, non_negative_time_us());
  double width = 0.0;
  if (r.read("width_us", width, Need::optional, positive_duration_us())) ch.width_us = width;

  // The gpio backend drives every channel itself, unless an external pulse generator makes
  // the µs timing: then only the generator's trigger input needs a GPIO line, and channels
  // without chip/line are the generator's outputs.
  const bool must_be_wired = ctx.gpio && (!ctx.has_pulse_generator || (role_known && ch.role == ChannelRole::pulse_generator));
  const bool has_chip = r.has("chip"), has_line = r.has("line");
  r.read("chip", ch.chip, Need::optional, not_empty());
  r.read("line", ch.line, Need::optional, at_least(0));
  const char* why = ctx.has_pulse_generator
                        ? "the gpio backend triggers the pulse generator through this line"
                        : "the gpio backend drives every channel (without a pulse_generator channel)";
  if (must_be_wired) {
    if (!has_chip) r.issue("chip", fmt::format("required key is missing (expected a string, e.g. \"gpiochip0\"): {}", why));
    if (!has_line) r.issue("line", fmt::format("required key is missing (expected an integer >= 0): {}", why));
  } else if (has_chip != has_line) {
    // A GPIO output is a chip and a line; half of one is a typo, not a choice.
    r.issue(has_chip ? "line" : "chip", fmt::format("required when {} is given: a GPIO output needs both chip and line",
                                                    has_chip ? "chip" : "line"));
  }
}

}  // namespace

void decode_trigger_channels(TableReader& trigger, bool gpio, const std::vector<LightSourceConfig>& sources,
                             std::vector<TriggerChannel>& channels) {
  // A GPIO trigger without a channel would pulse nothing.
  auto readers = trigger.array_of_tables("channels", gpio ? Need::required : Need::optional);
  // Roles first: whether a pulse generator exists decides which channels need GPIO wiring.
  std::vector<TriggerChannel> decoded(readers.size());
  std::vector<bool> role_known(readers.size());
  for (std::size_t i = 0; i < readers.size(); ++i) {
    readers[i].read("name", decoded[i].name, Need::required, not_empty());
    role_known[i] = readers[i].read_choice("role", decoded[i].role, Need::required);
  }
  ChannelContext ctx;
  ctx.gpio = gpio;
  ctx.sources = &sources;
  ctx.has_pulse_generator =
      std::any_of(decoded.begin(), decoded.end(), [](const TriggerChannel& c) { return c.role == ChannelRole::pulse_generator; });

  std::map<std::string, FirstUse> names;
  std::map<std::pair<std::string, int>, FirstUse> wires;
  for (std::size_t i = 0; i < readers.size(); ++i) {
    TableReader& r = readers[i];
    TriggerChannel& channel = decoded[i];
    decode_light_source_ref(r, ctx, role_known[i], channel);
    decode_timing_and_wiring(r, ctx, role_known[i], channel);
    r.report_unknown_keys();
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

}  // namespace tomorig::config::detail
