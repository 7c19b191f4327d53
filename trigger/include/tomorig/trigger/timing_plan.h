#pragma once
// Frame straddling for double-frame cameras: where every output edge of one trigger period
// lies, given the rate, the pulse separation, the light sources, the camera and the wiring.
//
// Time model (docs/trigger.md has the diagram): a double-frame camera, triggered once, exposes
// frame A, is blind for the interframe time, then exposes frame B. A single-frame camera
// (FrameMode::two_triggers) is triggered twice, once per frame, and needs its readout time
// between the end of frame A and the second trigger. Light pulse 1 must lie inside frame A and
// pulse 2 inside frame B, with dt between the pulse centres. Each output channel
// fires its electrical edge early by its own delay (camera trigger latency, LED driver rise
// time, Q-switch build-up) so that the optical event lands where planned. All times are integer
// nanoseconds; the period starts (t = 0) at the earliest edge of any channel.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/trigger/safety_limits.h"

namespace tomorig::trigger {

// camera, light, flashlamp, pulse_generator: what an output drives. Its words and to_string()
// are the rig file's (config/rig_vocabulary.h).
using ChannelRole = config::ChannelRole;

// How the triggered cameras make frames A and B.
enum class FrameMode : std::uint8_t {
  hardware,      // one trigger; the camera exposes A, waits the interframe time, exposes B
  two_triggers,  // one trigger per frame; frame B needs the readout time after frame A
};
std::string_view to_string(FrameMode mode);

// Which of the two straddled pulses a light (or flash-lamp) channel makes: one head of a
// dual-cavity laser makes one, an LED makes both (first, second, both; config/rig_vocabulary.h).
using PulseSelect = config::PulseSelect;

// A light source: what the safety limits and pulse widths belong to. Several channels may
// refer to one source (a laser head's flash lamp and Q-switch).
struct LightSource {
  std::string name;
  LightSourceKind kind = LightSourceKind::unknown;
  std::int64_t pulse_width_ns = 10;    // optical pulse width (LED: the current pulse)
  std::int64_t flashlamp_lead_ns = 0;  // laser: flash lamp → Q-switch delay (e.g. 180 µs)
  SafetyLimits limits;                 // unset fields take the kind's built-in defaults
};

struct ChannelSpec {
  std::string name;
  ChannelRole role = ChannelRole::camera;
  std::string light_source;                   // light and flashlamp channels: LightSource::name
  PulseSelect pulses = PulseSelect::both;     // light and flashlamp channels
  std::int64_t delay_ns = 0;  // edge → effect: camera latency, LED rise time, Q-switch build-up,
                              // pulse generator insertion delay
  std::int64_t width_ns = 0;  // electrical pulse width; 0: the light source's pulse width
                              // (light), 10 µs otherwise
  std::string chip;           // GPIO wiring; empty chip: made by the external pulse generator
  int line = -1;
  bool wired() const { return !chip.empty() && line >= 0; }
};

// The camera's double-frame timing (identical cameras; per-camera latency is ChannelSpec::delay_ns).
struct CameraTiming {
  std::int64_t exposure_a_ns = 20'000;    // frame A exposure, set on the camera (two_triggers: both frames)
  std::int64_t interframe_ns = 120;       // hardware: blind time between frames A and B (sCMOS: ~120 ns)
  std::int64_t exposure_b_ns = 1'000'000; // hardware: frame B lasts until frame A is read out
  std::int64_t readout_ns = 0;            // two_triggers: least time from the end of an exposure
                                          // to the next trigger the camera takes (> 0)
  FrameMode mode = FrameMode::hardware;
};

struct TimingInputs {
  double rate_hz = 10.0;       // double-frame events per second
  std::int64_t dt_ns = 100'000;  // separation of the centres of light pulses 1 and 2
  CameraTiming camera;
  std::vector<LightSource> light_sources;
  std::vector<ChannelSpec> channels;
};

// One high interval of an output, [rise_ns, fall_ns), relative to the period start.
struct Pulse {
  std::int64_t rise_ns = 0;
  std::int64_t fall_ns = 0;
  std::int64_t width_ns() const { return fall_ns - rise_ns; }
  bool operator==(const Pulse&) const = default;
};

struct ChannelTiming {
  ChannelSpec spec;
  std::vector<Pulse> pulses;  // electrical high intervals in one period, in time order
};

struct TimingPlan {
  double rate_hz = 0.0;
  std::int64_t period_ns = 0;
  std::int64_t dt_ns = 0;
  CameraTiming camera;
  // Optical events, relative to the period start.
  Pulse frame_a;        // exposure of frame A
  Pulse frame_b;        // exposure of frame B
  Pulse light_pulse_1;  // extent of the widest source making pulse 1
  Pulse light_pulse_2;
  // The camera could slide by ± this much and both pulses would still be inside their
  // frames: the slack that timing jitter may use up.
  std::int64_t straddle_margin_ns = 0;
  std::vector<LightSource> light_sources;
  std::vector<ChannelTiming> channels;

  // Where B - A of a camera's own frame timestamps should come out: the start of frame B
  // after the start of frame A (two_triggers: dt; hardware: exposure A + interframe).
  std::int64_t frame_separation_ns() const { return frame_b.rise_ns - frame_a.rise_ns; }

  const ChannelTiming* find_channel(std::string_view name) const;
  const LightSource* find_light_source(std::string_view name) const;
  bool has_pulse_generator() const;
};

// Checks the inputs and computes every edge. Throws tomorig::Error (bad_input) naming the
// quantity, its value and the bound it breaks ("dt 0.1 us is shorter than ...").
TimingPlan plan_timing(const TimingInputs& inputs);

// Nanoseconds as microseconds for messages: "12.5 us".
std::string format_us(std::int64_t ns);

}  // namespace tomorig::trigger
