#pragma once
// The enums of the rig configuration and the words that spell them in the rig file (read and
// written through vocabulary.h's parse / to_string). The TOML spelling is part of the file
// format: docs/configuration.md lists it, and a renamed word breaks every rig file.
#include <cstdint>

#include "tomorig/config/vocabulary.h"

namespace tomorig::config {

enum class CameraBackend : std::uint8_t { aravis, simulated, gentl };
template <>
struct Vocabulary<CameraBackend> {
  static constexpr Word<CameraBackend> words[] = {
      {"aravis", CameraBackend::aravis}, {"simulated", CameraBackend::simulated}, {"gentl", CameraBackend::gentl}};
};

enum class TriggerBackend : std::uint8_t { gpio, simulated };
template <>
struct Vocabulary<TriggerBackend> {
  static constexpr Word<TriggerBackend> words[] = {{"gpio", TriggerBackend::gpio},
                                                   {"simulated", TriggerBackend::simulated}};
};

// How a camera makes the two frames of a set (docs/configuration.md, frame_mode).
enum class FrameMode : std::uint8_t {
  hardware,      // one trigger, two frames: a PIV double-shutter camera
  two_triggers,  // a single-frame camera, triggered at pulse 1 and again at pulse 2
  free_run,      // not triggered: frames are unsynchronised, no set is ever complete
};
template <>
struct Vocabulary<FrameMode> {
  static constexpr Word<FrameMode> words[] = {{"hardware", FrameMode::hardware},
                                              {"two_triggers", FrameMode::two_triggers},
                                              {"free_run", FrameMode::free_run}};
};

// What a light source is ([[trigger.light_sources]] kind); the trigger's built-in safety limits
// depend on it.
enum class LightSourceKind : std::uint8_t {
  laser,    // Q-switched (flash-lamp pumped) laser head
  led,      // current-pulsed, usually overdriven LED
  unknown,  // not stated in the rig file (no word): the strictest limit of every kind applies
};
template <>
struct Vocabulary<LightSourceKind> {
  static constexpr Word<LightSourceKind> words[] = {{"laser", LightSourceKind::laser}, {"led", LightSourceKind::led}};
};

// What a trigger output drives ([[trigger.channels]] role).
enum class ChannelRole : std::uint8_t {
  camera,           // exposure trigger of a double-frame camera (one trigger: frames A and B)
  light,            // the edge that makes light: LED driver input, laser Q-switch
  flashlamp,        // a laser head's flash lamp, fired `flashlamp_lead` before its Q-switch
  pulse_generator,  // trigger input of an external delay generator that makes the µs pulses
};
template <>
struct Vocabulary<ChannelRole> {
  static constexpr Word<ChannelRole> words[] = {{"light", ChannelRole::light},
                                                {"camera", ChannelRole::camera},
                                                {"flashlamp", ChannelRole::flashlamp},
                                                {"pulse_generator", ChannelRole::pulse_generator}};
};
// Light and flash-lamp channels fire a light source and choose its pulses.
constexpr bool drives_light(ChannelRole role) { return role == ChannelRole::light || role == ChannelRole::flashlamp; }

// Which of the two pulses of a set a light or flash-lamp channel fires ([[trigger.channels]] pulses).
enum class PulseSelect : std::uint8_t { first, second, both };
template <>
struct Vocabulary<PulseSelect> {
  static constexpr Word<PulseSelect> words[] = {
      {"first", PulseSelect::first}, {"second", PulseSelect::second}, {"both", PulseSelect::both}};
};

// The simulated light sheet's intensity across its thickness ([simulation] light_sheet).
enum class LightSheetProfile : std::uint8_t { uniform, gaussian, tophat };
template <>
struct Vocabulary<LightSheetProfile> {
  static constexpr Word<LightSheetProfile> words[] = {{"uniform", LightSheetProfile::uniform},
                                                      {"gaussian", LightSheetProfile::gaussian},
                                                      {"tophat", LightSheetProfile::tophat}};
};

// The spray-thesis case's droplet pattern ([simulation] spray).
enum class SprayPattern : std::uint8_t { jet_in_crossflow, hollow_cone };
template <>
struct Vocabulary<SprayPattern> {
  static constexpr Word<SprayPattern> words[] = {{"jet-in-crossflow", SprayPattern::jet_in_crossflow},
                                                 {"hollow-cone", SprayPattern::hollow_cone}};
};

}  // namespace tomorig::config
