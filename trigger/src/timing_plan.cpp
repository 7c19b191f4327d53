// Frame-straddling geometry: optical events first (pulses, then the camera window placed to
// give both pulses the most slack), then each channel's electrical edges, early by its delay.
#include "tomorig/trigger/timing_plan.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::trigger {
namespace {

constexpr std::int64_t kDefaultOutputWidthNs = 10'000;  // a TTL trigger pulse most inputs accept
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::max();

bool makes(PulseSelect select, int pulse) {
  return select == PulseSelect::both || (pulse == 1 ? select == PulseSelect::first : select == PulseSelect::second);
}

// Collects every problem, so one run of `tomorig trigger plan` shows them all.
class Problems {
 public:
  template <typename... Args>
  void add(fmt::format_string<Args...> format, Args&&... args) {
    lines_.push_back(fmt::format(format, std::forward<Args>(args)...));
  }
  void throw_if_any() const {
    if (lines_.empty()) return;
    std::string message = lines_.size() == 1 ? std::string("infeasible trigger plan: ")
                                             : fmt::format("infeasible trigger plan ({} problems):\n  ", lines_.size());
    for (std::size_t i = 0; i < lines_.size(); ++i) message += (i ? "\n  " : "") + lines_[i];
    throw bad_input(message);
  }

 private:
  std::vector<std::string> lines_;
};

void check_inputs(const TimingInputs& in, Problems& problems) {
  if (!(std::isfinite(in.rate_hz) && in.rate_hz > 0.0))
    problems.add("rate {} Hz must be > 0", in.rate_hz);
  if (in.dt_ns <= 0) problems.add("dt {} must be > 0", format_us(in.dt_ns));
  if (in.camera.exposure_a_ns <= 0) problems.add("camera exposure A {} must be > 0", format_us(in.camera.exposure_a_ns));
  if (in.camera.exposure_b_ns <= 0) problems.add("camera exposure B {} must be > 0", format_us(in.camera.exposure_b_ns));
  if (in.camera.interframe_ns < 0)
    problems.add("camera interframe time {} must be >= 0", format_us(in.camera.interframe_ns));
  if (in.camera.mode == FrameMode::two_triggers && in.camera.readout_ns <= 0)
    problems.add("frame mode two_triggers needs the camera's readout time (> 0): a single-frame camera cannot take "
                 "the second trigger before frame A is read out");

  std::set<std::string> sources;
  for (const auto& s : in.light_sources) {
    if (!sources.insert(s.name).second) problems.add("light source '{}' is defined twice", s.name);
    if (s.pulse_width_ns <= 0)
      problems.add("light source '{}': pulse width {} must be > 0", s.name, format_us(s.pulse_width_ns));
    if (s.flashlamp_lead_ns < 0)
      problems.add("light source '{}': flash lamp lead {} must be >= 0", s.name, format_us(s.flashlamp_lead_ns));
  }

  if (in.channels.empty()) problems.add("no output channels: add at least a camera and a light channel");
  std::set<std::string> names;
  bool camera = false, pulse1 = false, pulse2 = false;
  for (const auto& c : in.channels) {
    if (!names.insert(c.name).second) problems.add("channel '{}' is defined twice", c.name);
    if (c.delay_ns < 0) problems.add("channel '{}': delay {} must be >= 0", c.name, format_us(c.delay_ns));
    if (c.width_ns < 0) problems.add("channel '{}': width {} must be >= 0", c.name, format_us(c.width_ns));
    camera = camera || c.role == ChannelRole::camera;
    if (c.role == ChannelRole::light || c.role == ChannelRole::flashlamp) {
      if (!sources.count(c.light_source)) {
        problems.add("channel '{}' ({}) drives light source '{}', which is not defined", c.name, to_string(c.role),
                     c.light_source);
        continue;
      }
    }
    if (c.role == ChannelRole::light) {
      pulse1 = pulse1 || makes(c.pulses, 1);
      pulse2 = pulse2 || makes(c.pulses, 2);
    }
    if (c.role == ChannelRole::flashlamp) {
      const bool has_qswitch = std::any_of(in.channels.begin(), in.channels.end(), [&](const ChannelSpec& q) {
        return q.role == ChannelRole::light && q.light_source == c.light_source;
      });
      if (!has_qswitch)
        problems.add("flash-lamp channel '{}': light source '{}' has no light (Q-switch) channel to lead", c.name,
                     c.light_source);
    }
  }
  if (!in.channels.empty()) {
    if (!camera) problems.add("no camera channel: frame straddling needs a camera trigger");
    if (!pulse1) problems.add("no light channel makes pulse 1 (frame A)");
    if (!pulse2) problems.add("no light channel makes pulse 2 (frame B)");
  }
}

const LightSource& source_of(const TimingInputs& in, const ChannelSpec& c) {
  return *std::find_if(in.light_sources.begin(), in.light_sources.end(),
                       [&](const LightSource& s) { return s.name == c.light_source; });
}

// Optical pulse of `source` centred on `centre_ns`.
Pulse optical_pulse(const LightSource& source, std::int64_t centre_ns) {
  const std::int64_t rise = centre_ns - source.pulse_width_ns / 2;
  return {rise, rise + source.pulse_width_ns};
}

// The union of all sources' pulses k: the light the camera must catch in one frame.
Pulse light_extent(const TimingInputs& in, int k, std::int64_t centre_ns) {
  Pulse extent{kNever, std::numeric_limits<std::int64_t>::min()};
  for (const auto& c : in.channels) {
    if (c.role != ChannelRole::light || !makes(c.pulses, k)) continue;
    const Pulse p = optical_pulse(source_of(in, c), centre_ns);
    extent.rise_ns = std::min(extent.rise_ns, p.rise_ns);
    extent.fall_ns = std::max(extent.fall_ns, p.fall_ns);
  }
  return extent;
}

void shift(Pulse& p, std::int64_t by) {
  p.rise_ns += by;
  p.fall_ns += by;
}


// Double-frame camera: x is the end of frame A. Pulse 1 inside A and pulse 2 inside B give
// four bounds; x goes in the middle of what they leave, so jitter either way has the same slack.
void place_double_frame_windows(const TimingInputs& in, const Pulse& p1, const Pulse& p2, TimingPlan& plan,
                                Problems& problems) {
  const auto& cam = in.camera;
  const std::int64_t lo = std::max(p1.fall_ns, p2.fall_ns - cam.interframe_ns - cam.exposure_b_ns);
  const std::int64_t hi = std::min(p1.rise_ns + cam.exposure_a_ns, p2.rise_ns - cam.interframe_ns);
  if (lo > hi) {
    const std::int64_t gap = p2.rise_ns - p1.fall_ns;
    if (gap < cam.interframe_ns)
      problems.add("dt {} is too short for the camera: between light pulse 1 and pulse 2 there are {}, less than the "
                   "interframe time {}; dt must be >= {}",
                   format_us(in.dt_ns), format_us(gap), format_us(cam.interframe_ns),
                   format_us(in.dt_ns + cam.interframe_ns - gap));
    if (p1.width_ns() > cam.exposure_a_ns)
      problems.add("light pulse 1 ({} wide) does not fit in the frame A exposure {}; exposure A must be >= {}",
                   format_us(p1.width_ns()), format_us(cam.exposure_a_ns), format_us(p1.width_ns()));
    if (p2.width_ns() > cam.exposure_b_ns)
      problems.add("light pulse 2 ({} wide) does not fit in the frame B exposure {}; exposure B must be >= {}",
                   format_us(p2.width_ns()), format_us(cam.exposure_b_ns), format_us(p2.width_ns()));
    const std::int64_t span = p2.fall_ns - p1.rise_ns;
    const std::int64_t window = cam.exposure_a_ns + cam.interframe_ns + cam.exposure_b_ns;
    if (span > window)
      problems.add("dt {} is too long for the camera: the pulses span {} but frame A + interframe + frame B last {}; "
                   "dt must be <= {}",
                   format_us(in.dt_ns), format_us(span), format_us(window), format_us(in.dt_ns - (span - window)));
    problems.throw_if_any();
  }
  const std::int64_t frame_a_end = lo + (hi - lo) / 2;
  plan.straddle_margin_ns = (hi - lo) / 2;
  plan.frame_a = {frame_a_end - cam.exposure_a_ns, frame_a_end};
  plan.frame_b = {frame_a_end + cam.interframe_ns, frame_a_end + cam.interframe_ns + cam.exposure_b_ns};
}

// Single-frame camera triggered twice: frames A and B both last exposure A (the camera has one
// ExposureTime), each centred on its pulse when the readout allows; otherwise A moves earlier
// and B later by the same amount until the readout fits between them. What is left of either
// frame's slack around its pulse is the straddle margin.
void place_single_frame_windows(const TimingInputs& in, const Pulse& p1, const Pulse& p2, TimingPlan& plan,
                                Problems& problems) {
  const auto& cam = in.camera;
  const std::int64_t exposure = cam.exposure_a_ns;
  for (const auto& [k, p] : {std::pair{1, p1}, std::pair{2, p2}})
    if (p.width_ns() > exposure)
      problems.add("light pulse {} ({} wide) does not fit in the exposure {} of a frame; exposure A (both frames of a "
                   "two_triggers camera) must be >= {}",
                   k, format_us(p.width_ns()), format_us(exposure), format_us(p.width_ns()));
  const std::int64_t gap = p2.rise_ns - p1.fall_ns;  // the most the camera can have between A's end and B's start
  if (gap < cam.readout_ns)
    problems.add("dt {} is too short for single-frame cameras triggered twice (frame_mode two_triggers): between light "
                 "pulse 1 and pulse 2 there are {}, less than the camera's readout time {}, so frame B could not "
                 "start before pulse 2; dt must be >= {} (or use double-frame cameras, frame_mode hardware)",
                 format_us(in.dt_ns), format_us(gap), format_us(cam.readout_ns),
                 format_us(in.dt_ns + cam.readout_ns - gap));
  problems.throw_if_any();
  // Centred: A ends at the middle of [p1.fall, p1.rise + exposure], B starts at the middle of
  // [p2.fall - exposure, p2.rise].
  std::int64_t a_end = p1.fall_ns + (p1.rise_ns + exposure - p1.fall_ns) / 2;
  std::int64_t b_start = p2.fall_ns - exposure + (p2.rise_ns - (p2.fall_ns - exposure)) / 2;
  const std::int64_t short_by = cam.readout_ns - (b_start - a_end);
  if (short_by > 0) {
    a_end -= short_by / 2;
    b_start += short_by - short_by / 2;
  }
  a_end = std::max(a_end, p1.fall_ns);
  b_start = std::min(b_start, p2.rise_ns);
  plan.frame_a = {a_end - exposure, a_end};
  plan.frame_b = {b_start, b_start + exposure};
  plan.straddle_margin_ns = std::min({a_end - p1.fall_ns, p1.rise_ns - plan.frame_a.rise_ns, b_start + exposure - p2.fall_ns,
                                      p2.rise_ns - b_start});
}

}  // namespace

std::string format_us(std::int64_t ns) {
  std::string s = fmt::format("{:.3f}", static_cast<double>(ns) / 1000.0);
  while (!s.empty() && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s + " us";
}

std::string_view to_string(FrameMode mode) {
  return mode == FrameMode::two_triggers ? "two_triggers" : "hardware";
}

const ChannelTiming* TimingPlan::find_channel(std::string_view name) const {
  for (const auto& c : channels)
    if (c.spec.name == name) return &c;
  return nullptr;
}

const LightSource* TimingPlan::find_light_source(std::string_view name) const {
  for (const auto& s : light_sources)
    if (s.name == name) return &s;
  return nullptr;
}

bool TimingPlan::has_pulse_generator() const {
  return std::any_of(channels.begin(), channels.end(),
                     [](const ChannelTiming& c) { return c.spec.role == ChannelRole::pulse_generator; });
}

TimingPlan plan_timing(const TimingInputs& in) {
  Problems problems;
  check_inputs(in, problems);
  problems.throw_if_any();

  TimingPlan plan;
  plan.rate_hz = in.rate_hz;
  plan.period_ns = std::llround(1e9 / in.rate_hz);
  plan.dt_ns = in.dt_ns;
  plan.camera = in.camera;
  plan.light_sources = in.light_sources;

  // 1. Light: pulse 1 centred at 0, pulse 2 at dt (dt is centre to centre: the time that turns
  //    a displacement into a velocity, even when the two pulses differ in width).
  const Pulse p1 = light_extent(in, 1, 0);
  const Pulse p2 = light_extent(in, 2, in.dt_ns);
  plan.light_pulse_1 = p1;
  plan.light_pulse_2 = p2;

  // 2. Camera windows.
  if (in.camera.mode == FrameMode::two_triggers)
    place_single_frame_windows(in, p1, p2, plan, problems);
  else
    place_double_frame_windows(in, p1, p2, plan, problems);

  // 3. Electrical edges, early by each channel's delay. Light before flash lamps (a flash lamp
  //    leads its Q-switch edge) before the pulse generator (which leads everything it makes).
  plan.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) plan.channels[i].spec = in.channels[i];
  for (auto& ch : plan.channels) {
    const auto& c = ch.spec;
    const std::int64_t width = c.width_ns > 0 ? c.width_ns : kDefaultOutputWidthNs;
    if (c.role == ChannelRole::camera) {
      ch.pulses.push_back({plan.frame_a.rise_ns - c.delay_ns, plan.frame_a.rise_ns - c.delay_ns + width});
      if (in.camera.mode == FrameMode::two_triggers)  // the second trigger starts frame B
        ch.pulses.push_back({plan.frame_b.rise_ns - c.delay_ns, plan.frame_b.rise_ns - c.delay_ns + width});
    } else if (c.role == ChannelRole::light) {
      const LightSource& s = source_of(in, c);
      const std::int64_t w = c.width_ns > 0 ? c.width_ns : s.pulse_width_ns;
      for (int k = 1; k <= 2; ++k) {
        if (!makes(c.pulses, k)) continue;
        const std::int64_t rise = optical_pulse(s, k == 1 ? 0 : in.dt_ns).rise_ns - c.delay_ns;
        ch.pulses.push_back({rise, rise + w});
      }
    }
  }
  for (auto& ch : plan.channels) {
    const auto& c = ch.spec;
    if (c.role != ChannelRole::flashlamp) continue;
    const LightSource& s = source_of(in, c);
    const std::int64_t width = c.width_ns > 0 ? c.width_ns : kDefaultOutputWidthNs;
    for (int k = 1; k <= 2; ++k) {
      if (!makes(c.pulses, k)) continue;
      std::int64_t qswitch = kNever;  // earliest Q-switch edge of this source for pulse k
      for (const auto& q : plan.channels)
        if (q.spec.role == ChannelRole::light && q.spec.light_source == c.light_source && makes(q.spec.pulses, k))
          qswitch = std::min(qswitch, q.pulses[(q.spec.pulses == PulseSelect::both && k == 2) ? 1 : 0].rise_ns);
      if (qswitch == kNever) {
        problems.add("flash-lamp channel '{}' fires for pulse {} but no light channel of '{}' makes pulse {}", c.name, k,
                     c.light_source, k);
        continue;
      }
      const std::int64_t rise = qswitch - s.flashlamp_lead_ns - c.delay_ns;
      ch.pulses.push_back({rise, rise + width});
    }
  }
  problems.throw_if_any();
  std::int64_t earliest = kNever;
  for (const auto& ch : plan.channels)
    for (const auto& p : ch.pulses) earliest = std::min(earliest, p.rise_ns);
  for (auto& ch : plan.channels) {
    const auto& c = ch.spec;
    if (c.role != ChannelRole::pulse_generator) continue;
    const std::int64_t width = c.width_ns > 0 ? c.width_ns : kDefaultOutputWidthNs;
    ch.pulses.push_back({earliest - c.delay_ns, earliest - c.delay_ns + width});
  }

  // 4. The period starts at the earliest edge.
  earliest = kNever;
  for (const auto& ch : plan.channels)
    for (const auto& p : ch.pulses) earliest = std::min(earliest, p.rise_ns);
  const std::int64_t by = -earliest;
  for (auto& ch : plan.channels)
    for (auto& p : ch.pulses) shift(p, by);
  for (Pulse* p : {&plan.frame_a, &plan.frame_b, &plan.light_pulse_1, &plan.light_pulse_2}) shift(*p, by);

  // 5. What must hold inside one period.
  for (const auto& ch : plan.channels) {
    for (std::size_t k = 1; k < ch.pulses.size(); ++k)
      if (ch.pulses[k].rise_ns < ch.pulses[k - 1].fall_ns)
        problems.add("channel '{}': its pulse for frame B (rises at {}) starts before its pulse for frame A ends ({}); "
                     "shorten the pulse or raise dt above {}",
                     ch.spec.name, format_us(ch.pulses[k].rise_ns), format_us(ch.pulses[k - 1].fall_ns),
                     format_us(in.dt_ns + ch.pulses[k - 1].fall_ns - ch.pulses[k].rise_ns));
  }
  // A single-frame camera must have read frame B out before the next event's first trigger.
  std::int64_t last = plan.frame_b.fall_ns + (in.camera.mode == FrameMode::two_triggers ? in.camera.readout_ns : 0);
  for (const auto& ch : plan.channels)
    for (const auto& p : ch.pulses) last = std::max(last, p.fall_ns);
  if (last > plan.period_ns)
    problems.add("one event needs {} (first edge to the end of frame B{} or the last edge), longer than the period {} "
                 "at {} Hz; lower the rate to <= {:.6g} Hz or shorten exposure B / flash-lamp lead",
                 format_us(last), in.camera.mode == FrameMode::two_triggers ? " and its readout" : "",
                 format_us(plan.period_ns), in.rate_hz, 1e9 / static_cast<double>(last));
  problems.throw_if_any();
  return plan;
}

}  // namespace tomorig::trigger
