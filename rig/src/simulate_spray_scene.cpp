// spray-thesis as the live simulated rig's scene: the rig file's four simulated cameras take
// the case's four views (Table 7.2) in order, under their own ids; [simulation] chooses the
// seed, the pattern (spray), noise and LED pulse B's energy; the trigger's dt_us is the pulse
// separation. The views' geometry and PSF are the case's: the cameras' yaw, focal length and
// distance do not apply (docs/spray.md).
#include <cmath>
#include <utility>

#include <fmt/core.h>

#include "simulate_spray_truth.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/simulate_spray.h"
#include "tomorig/rig/simulated_scene.h"

namespace tomorig::rig {
namespace {

// The two image sizes the case renders: full (sCMOS 2560 x 2160) and reduced (640 x 540).
constexpr int kFullWidth = 2560, kFullHeight = 2160, kReducedWidth = 640, kReducedHeight = 540;

sim::SprayOptions spray_options_from(const config::RigConfig& rig) {
  if (!rig.simulation)
    throw bad_input("the rig has simulated cameras but no [simulation] table; add one (see 'tomorig config default')");
  const config::SimulationConfig& s = *rig.simulation;
  constexpr std::size_t kViews = 4;
  if (rig.cameras.size() != kViews)
    throw bad_input(fmt::format("simulation.case = \"spray-thesis\" renders {} views but the rig has {} cameras: give it "
                                "exactly {} [[cameras]] with backend = \"simulated\"",
                                kViews, rig.cameras.size(), kViews));
  if (s.bit_depth != 16)
    throw bad_input(fmt::format("simulation.bit_depth = {}: spray-thesis renders 16-bit images; set bit_depth = 16",
                                s.bit_depth));
  bool reduced = false;
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const config::CameraConfig& c = rig.cameras[i];
    if (c.backend != config::CameraBackend::simulated)
      throw bad_input(fmt::format("cameras[{}] ('{}') uses the {} backend: spray-thesis needs every camera to use "
                                  "backend = \"simulated\"",
                                  i, c.id, config::to_string(c.backend)));
    if (c.pixel_format != PixelFormat::Mono16)
      throw bad_input(fmt::format("cameras[{}] ('{}') has pixel_format = \"{}\": spray-thesis renders Mono16; set "
                                  "pixel_format = \"Mono16\"",
                                  i, c.id, to_string(c.pixel_format)));
    const bool full = c.roi.width == kFullWidth && c.roi.height == kFullHeight;
    const bool small = c.roi.width == kReducedWidth && c.roi.height == kReducedHeight;
    if (!full && !small)
      throw bad_input(fmt::format("cameras[{}] ('{}'): roi {} x {} is not a spray-thesis image: use {} x {} (full) or "
                                  "{} x {} (reduced)",
                                  i, c.id, c.roi.width, c.roi.height, kFullWidth, kFullHeight, kReducedWidth,
                                  kReducedHeight));
    if (i > 0 && small != reduced)
      throw bad_input(fmt::format("cameras[{}] ('{}'): roi {} x {} differs from cameras[0]'s: spray-thesis cameras are "
                                  "all full ({} x {}) or all reduced ({} x {})",
                                  i, c.id, c.roi.width, c.roi.height, kFullWidth, kFullHeight, kReducedWidth,
                                  kReducedHeight));
    reduced = small;
  }
  sim::SprayOptions o;
  o.reduced = reduced;
  o.seed = s.seed;
  o.pattern = sim_spray_pattern(s.spray);
  o.noise = s.noise;
  o.pulse_b_energy = s.pulse_b_energy;
  o.dt_us = rig.trigger.dt_us;
  return o;
}

class SprayScene final : public SimulatedScene {
 public:
  explicit SprayScene(const config::RigConfig& rig)
      : case_(sim::make_spray_thesis_case(spray_options_from(rig))), rate_hz_(rig.trigger.rate_hz) {
    if (!(rate_hz_ > 0)) throw bad_input(fmt::format("trigger.rate_hz = {} must be > 0", rate_hz_));
    // The rig's ids name the views, everywhere the case names them (truth, optics set-up).
    for (std::size_t k = 0; k < case_.cameras.size(); ++k) {
      case_.cameras[k].id = rig.cameras[k].id;
      case_.optics.cameras[k].id = rig.cameras[k].id;
      const sim::SprayCamera& cam = case_.cameras[k];
      cameras_.push_back({cam.id, cam.width, cam.height, PixelFormat::Mono16, cam.pixel_pitch_um});
    }
  }
  const std::vector<storage::SessionCamera>& cameras() const override { return cameras_; }
  storage::SessionTruth truth() const override {
    return spray_truth(case_, sim::to_string(case_.options.pattern), spray_parameters_json(case_));
  }
  std::size_t particles_per_set() const override { return static_cast<std::size_t>(case_.options.droplets); }
  std::int64_t nominal_dt_ns() const override { return std::llround(case_.options.dt_us * 1e3); }
  SceneSet render(std::uint64_t index, std::int64_t dt_ns) const override {
    sim::SpraySet s = sim::render_spray_set(case_, index, dt_ns);
    SceneSet out;
    out.frames = std::move(s.frames);
    out.frames.trigger_timestamp_ns = std::llround(static_cast<double>(index) * 1e9 / rate_hz_);
    for (CameraFrames& cf : out.frames.cameras) {
      cf.a.timestamp_ns += out.frames.trigger_timestamp_ns;
      cf.b.timestamp_ns += out.frames.trigger_timestamp_ns;
    }
    for (const sim::Droplet& d : s.droplets) {
      out.truth.particles_a.push_back(d.a);
      out.truth.particles_b.push_back(d.b);
    }
    return out;
  }

 private:
  sim::SprayCase case_;
  double rate_hz_;
  std::vector<storage::SessionCamera> cameras_;
};

}  // namespace

std::unique_ptr<SimulatedScene> make_spray_scene(const config::RigConfig& rig) {
  return std::make_unique<SprayScene>(rig);
}

}  // namespace tomorig::rig
