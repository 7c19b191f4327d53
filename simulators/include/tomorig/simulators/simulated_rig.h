#pragma once
// A simulated double-frame rig: a case (scene + flow + cameras) rendered set by set into the
// same FrameSets a live rig delivers, with the ground truth alongside.
//
//   sim::SimulationOptions opt;  opt.ppp = 0.05;  opt.seed = 7;
//   sim::SimulatedRig rig(opt);            // validates; throws bad_input
//   sim::SimulatedSet s = rig.render_set(0);  // s.frames: cameras x (A, B); s.particles_a/b
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/light_sheet.h"
#include "tomorig/simulators/particle_renderer.h"
#include "tomorig/simulators/sensor.h"

namespace tomorig::sim {

struct SimulationOptions {
  std::string case_name = "tpiv-thesis";
  double ppp = 0.05;       // particle images per pixel, in (0, 1]: N = ppp * W * H
  std::uint64_t seed = 1;  // recorded with the truth; set k uses seeds derived from (seed, k)
  // Cameras to render; empty: the case's own cameras.
  std::vector<SimulatedCameraSpec> cameras;
  double peak_counts = 1000.0;  // peak intensity of a fully lit particle image
  LightSheetProfile light_sheet = LightSheetProfile::uniform;
  bool noise = false;              // shot + read noise
  double read_noise_e = 5.0;       // electrons, 1 sigma
  double gain_counts_per_e = 1.0;  // counts per electron
  double rate_hz = 10.0;           // trigger rate: set k is triggered at k / rate
  std::int64_t dt_ns = 100'000;    // pulse separation A -> B
  int threads = 0;                 // OpenMP threads; 0: default. Never changes the images.

  // Throws tomorig::Error (bad_input) naming the field, its value and what is allowed.
  void validate() const;
};

// A camera of the rig with the model it is rendered through (the truth calibration).
struct SimulatedCamera {
  SimulatedCameraSpec spec;
  calibration::PinholeCamera model;
};

struct SimulatedSet {
  FrameSet frames;                 // cameras x (A, B), u16 Mono12/Mono16 images
  std::vector<Vec3d> particles_a;  // world mm at exposure A
  std::vector<Vec3d> particles_b;  // world mm at exposure B
};

class SimulatedRig {
 public:
  // Validates the options and builds the cameras and the flow; throws tomorig::Error
  // (bad_input) for an unknown case, ppp outside (0, 1], or a bad camera.
  explicit SimulatedRig(const SimulationOptions& options);

  const SimulationOptions& options() const { return options_; }
  const CaseDefinition& case_definition() const { return *case_; }
  const std::vector<SimulatedCamera>& cameras() const { return cameras_; }
  const Flow& flow() const { return *flow_; }
  const LightSheet& light_sheet() const { return sheet_; }
  std::size_t particles_per_set() const { return particles_per_set_; }

  // Mid-time particle positions of set k (seeded from (seed, k)).
  std::vector<Vec3d> particle_midpoints(std::uint64_t set_index) const;
  // Renders set k: a fresh particle field, moved by the flow, imaged by every camera.
  SimulatedSet render_set(std::uint64_t set_index) const;
  // Renders set k as triggered with an actual pulse separation `dt_ns` (a live rig's event,
  // jitter included): the flow's displacement scales with dt_ns / options().dt_ns, so a Δt
  // error shows up as a displacement error. The set records dt_ns, and frame B is stamped at
  // trigger time + dt_ns. With dt_ns == options().dt_ns it equals render_set(k) bit for bit.
  // Throws bad_input for dt_ns < 0, or dt_ns != 0 when options().dt_ns is 0 (no time base).
  SimulatedSet render_set(std::uint64_t set_index, std::int64_t dt_ns) const;
  // The noise-free float signal of camera `camera` for the given particles (for tests and
  // diagnostics; render_set digitises exactly this).
  Image render_signal(std::size_t camera, std::span<const Vec3d> particles) const;

 private:
  SimulationOptions options_;
  const CaseDefinition* case_;
  std::vector<SimulatedCamera> cameras_;
  std::unique_ptr<Flow> flow_;
  LightSheet sheet_;
  ParticleImageOptions image_options_;
  std::size_t particles_per_set_ = 0;
};

// N = round(ppp * mean of W * H over the cameras); with equal cameras, ppp * W * H.
std::size_t particle_count(double ppp, const std::vector<SimulatedCameraSpec>& cameras);

}  // namespace tomorig::sim
