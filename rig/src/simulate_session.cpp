#include "tomorig/rig/simulate_session.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <future>
#include <utility>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/rig/simulated_scene.h"

namespace tomorig::rig {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string human_bytes(std::uintmax_t bytes) {
  if (bytes >= 1024 * 1024) return fmt::format("{:.1f} MiB", bytes / (1024.0 * 1024.0));
  if (bytes >= 1024) return fmt::format("{:.1f} KiB", bytes / 1024.0);
  return fmt::format("{} B", bytes);
}

// The rig file's profile (config's word) as the simulator's own enum.
sim::LightSheetProfile sim_light_sheet(config::LightSheetProfile profile) {
  switch (profile) {
    case config::LightSheetProfile::uniform: return sim::LightSheetProfile::uniform;
    case config::LightSheetProfile::gaussian: return sim::LightSheetProfile::gaussian;
    case config::LightSheetProfile::tophat: return sim::LightSheetProfile::tophat;
  }
  return sim::LightSheetProfile::uniform;
}

}  // namespace

storage::TruthCamera truth_camera_of(const std::string& id, const calibration::PinholeCamera& model, int width,
                                     int height) {
  storage::TruthCamera t;
  t.id = id;
  t.K = model.intrinsics();
  t.R = model.parameters().R;
  t.t = model.parameters().t;
  t.width = width;
  t.height = height;
  return t;
}

storage::TruthCamera truth_camera_of(const sim::SimulatedCamera& cam) {
  storage::TruthCamera t = truth_camera_of(cam.spec.id, cam.model, cam.spec.width, cam.spec.height);
  t.model = cam.model.model_name();  // the rig's cameras are exactly this model
  return t;
}

std::string SimulationSummary::brief() const {
  return fmt::format("wrote {}: {}, {} set{} x {} cameras, {} particles per set, {} in {:.2f} s", output.string(),
                     case_name, sets, sets == 1 ? "" : "s", cameras, particles_per_set, human_bytes(bytes), seconds);
}

sim::SimulationOptions simulation_options_from(const config::RigConfig& rig) {
  if (!rig.simulation)
    throw bad_input("the rig config has no [simulation] section: a simulated session needs one "
                    "(see `tomorig config default`)");
  const config::SimulationConfig& s = *rig.simulation;
  if (s.bit_depth != 12 && s.bit_depth != 16)
    throw bad_input(fmt::format("simulation.bit_depth = {} is not supported: use 12 or 16", s.bit_depth));
  const PixelFormat format = s.bit_depth == 12 ? PixelFormat::Mono12 : PixelFormat::Mono16;

  sim::SimulationOptions o;
  o.case_name = s.case_name;
  o.ppp = s.ppp;
  o.seed = s.seed;
  o.noise = s.noise;
  o.read_noise_e = s.read_noise_e;
  o.peak_counts = s.peak_counts;
  o.light_sheet = sim_light_sheet(s.light_sheet);
  o.rate_hz = rig.trigger.rate_hz;
  o.dt_ns = std::llround(rig.trigger.dt_us * 1000.0);

  if (rig.cameras.empty()) throw bad_input("the rig config has no cameras: a simulated session needs at least one");
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    const config::CameraConfig& c = rig.cameras[i];
    if (c.backend != config::CameraBackend::simulated)
      throw bad_input(fmt::format("cameras[{}] ('{}') uses the {} backend: a simulated session needs every camera "
                                  "to use backend = \"simulated\"",
                                  i, c.id, config::to_string(c.backend)));
    // One quantisation for the whole rig: a camera recorded as Mono16 but quantised to 12 bit
    // (or the reverse) would mislabel its data.
    if (c.pixel_format != format)
      throw bad_input(fmt::format("cameras[{}] ('{}') has pixel_format = \"{}\" but simulation.bit_depth = {}: set "
                                  "pixel_format = \"{}\" or change the bit depth",
                                  i, c.id, to_string(c.pixel_format), s.bit_depth, to_string(format)));
    sim::SimulatedCameraSpec spec;
    spec.id = c.id;
    spec.yaw_deg = c.yaw_deg;
    spec.focal_length_mm = c.focal_length_mm;
    spec.pixel_pitch_um = c.pixel_pitch_um;
    spec.distance_mm = c.distance_mm;
    spec.width = c.roi.width;
    spec.height = c.roi.height;
    spec.pixel_format = c.pixel_format;
    if (spec.width <= 0 || spec.height <= 0)
      throw bad_input(fmt::format("cameras[{}] ('{}'): roi {} x {} is invalid: a simulated camera needs roi.width "
                                  "and roi.height > 0",
                                  i, c.id, spec.width, spec.height));
    o.cameras.push_back(spec);
  }
  return o;
}

SimulationSummary run_simulation_to_session(const config::RigConfig& rig, const std::filesystem::path& out,
                                            storage::Compression compression, bool overwrite,
                                            const SimulationProgress& progress, bool live,
                                            const std::function<bool()>& should_stop) {
  const auto start = Clock::now();
  // Everything that can be wrong with the input is found here, before a file exists.
  const std::unique_ptr<SimulatedScene> scene = make_simulated_scene(rig);
  const int sets = rig.simulation->sets;
  if (sets < 1) throw bad_input(fmt::format("simulation.sets = {} must be >= 1", sets));

  storage::SessionInfo info;
  info.cameras = scene->cameras();
  info.rig_config_toml = rig.source_text;
  info.software_version = std::string(software_version());
  info.compression = compression;

  storage::SessionWriterOptions writer_options;
  writer_options.live = live;
  writer_options.compression = compression;
  writer_options.overwrite = overwrite;
  storage::SessionWriter writer(out, info, writer_options);

  const storage::SessionTruth truth = scene->truth();
  writer.write_truth(truth);

  // Render set k + 1 while set k is written: the two take similar time on tpiv-thesis, and
  // the writer is single-threaded. At most two sets are in memory.
  auto render = [&scene](int k) { return scene->render(static_cast<std::uint64_t>(k), scene->nominal_dt_ns()); };
  std::future<SceneSet> next = std::async(std::launch::async, render, 0);
  auto previous_done = Clock::now();
  int written = 0;
  for (int k = 0; k < sets; ++k) {
    SceneSet set = next.get();
    if (should_stop && should_stop()) break;  // the set rendered ahead is dropped, never half-written
    if (k + 1 < sets) next = std::async(std::launch::async, render, k + 1);
    writer.append(set.frames);
    writer.write_truth_set(static_cast<std::uint64_t>(k), set.truth);
    if (progress) progress(static_cast<std::uint64_t>(k) + 1, static_cast<std::uint64_t>(sets), seconds_since(previous_done));
    previous_done = Clock::now();
    written = k + 1;
  }
  writer.finish();

  SimulationSummary summary;
  summary.case_name = truth.case_name;
  summary.sets = static_cast<std::uint64_t>(written);
  summary.cameras = scene->cameras().size();
  summary.particles_per_set = scene->particles_per_set();
  summary.output = out;
  std::error_code ec;
  const auto size = std::filesystem::file_size(out, ec);
  summary.bytes = ec ? 0 : size;
  summary.seconds = seconds_since(start);
  return summary;
}

}  // namespace tomorig::rig
