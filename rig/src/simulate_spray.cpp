// The spray-thesis case as a session file, truth alongside.
#include "tomorig/rig/simulate_spray.h"
#include "tomorig/rig/simulate_session.h"
#include "simulate_spray_truth.h"

#include <chrono>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/output_path.h"

namespace tomorig::rig {

std::string spray_optics_setup_toml(const sim::SprayCase& c) {
  std::string t = fmt::format(
      "# The optics of `tomorig simulate --case spray-thesis` (seed {}): chi_um is the true PSF half-width.\n"
      "liquid = \"{}\"\nd_max_um = {}\n\n[led]\npeak_nm = {}\nfwhm_nm = {}\nsamples = {}\n",
      c.options.seed, c.optics.liquid.name, c.optics.d_max_um, c.optics.spectrum.peak_nm, c.optics.spectrum.fwhm_nm,
      c.optics.spectrum.samples);
  for (const sim::SprayCamera& cam : c.cameras) {
    std::string z, chi;
    for (const optics::ChiSample& s : cam.chi) {
      z += (z.empty() ? "" : ", ") + fmt::format("{}", s.z_mm);
      chi += (chi.empty() ? "" : ", ") + fmt::format("{:.3f}", s.chi_um);
    }
    t += fmt::format("\n[[cameras]]\nid = \"{}\"\nf_number = {}\nmagnification = {}\nnoise = {}\nz_mm = [{}]\nchi_um = [{}]\n",
                     cam.id, cam.f_number, cam.magnification, cam.noise_sigma, z, chi);
  }
  return t;
}

std::string spray_rig_config_toml(const sim::SprayCase& c, int sets) {
  std::string t = fmt::format(
      "# The rig of `tomorig simulate --case spray-thesis`{}: `tomorig run --config` on this file records the same\n"
      "# images (docs/spray.md). The views' geometry and PSF are the case's own (Table 7.2), in this order.\n"
      "name = \"spray-thesis (simulated{})\"\n",
      c.options.reduced ? " --reduced" : "", c.options.reduced ? ", reduced" : "");
  for (const sim::SprayCamera& cam : c.cameras)
    t += fmt::format("\n[[cameras]]\nid = \"{}\"\nbackend = \"simulated\"\ndevice_id = \"{}\"\npixel_format = \"Mono16\"\n"
                     "pixel_pitch_um = {}\nyaw_deg = {}\n[cameras.roi]\nwidth = {}\nheight = {}\n",
                     cam.id, cam.id, cam.pixel_pitch_um, cam.yaw_deg, cam.width, cam.height);
  // The trigger as the session's timestamps have it: 25 Hz sets (Sect. 7.3), the two LED pulses
  // dt_us apart; the camera timing is the example rig's.
  t += fmt::format("\n[trigger]\nbackend = \"simulated\"\nrate_hz = 25.0\ndt_us = {}\npulse_width_us = 0.4\n\n"
                   "[trigger.camera]\nexposure_a_us = 1.0\ninterframe_us = 0.12\nexposure_b_us = 1000.0\n\n"
                   "[[trigger.light_sources]]\nname = \"leds\"\nkind = \"led\"\npulse_width_us = 0.4\n",
                   c.options.dt_us);
  t += fmt::format("\n[simulation]\ncase = \"spray-thesis\"\nseed = {}\nsets = {}\nbit_depth = 16\nnoise = {}\n"
                   "spray = \"{}\"\npulse_b_energy = {}\n",
                   c.options.seed, sets, c.options.noise ? "true" : "false", sim::to_string(c.options.pattern),
                   c.options.pulse_b_energy);
  return t;
}

nlohmann::json spray_cameras_json(const sim::SprayCase& c) {
  nlohmann::json cams = nlohmann::json::array();
  for (const sim::SprayCamera& cam : c.cameras) {
    nlohmann::json z = nlohmann::json::array(), chi = nlohmann::json::array();
    for (const optics::ChiSample& s : cam.chi) {
      z.push_back(s.z_mm);
      chi.push_back(s.chi_um);
    }
    cams.push_back({{"id", cam.id},
                    {"yaw_deg", cam.yaw_deg},
                    {"magnification", cam.magnification},
                    {"f_number", cam.f_number},
                    {"pixel_pitch_um", cam.pixel_pitch_um},
                    {"noise", cam.noise_sigma},
                    {"threshold", cam.threshold_value()},
                    {"z_mm", z},
                    {"chi_um", chi}});
  }
  return cams;
}

nlohmann::json spray_parameters_json(const sim::SprayCase& c) {
  return {{"pattern", sim::to_string(c.options.pattern)},
          {"reduced", c.options.reduced},
          {"droplets_per_set", c.options.droplets},
          {"d_median_um", c.options.d_median_um},
          {"d_log_sigma", c.options.d_log_sigma},
          {"d_range_um", {c.options.d_min_um, c.options.d_max_um}},
          {"dt_us", c.options.dt_us},
          {"bright_fraction", c.options.bright_fraction},
          {"vignetting", c.options.vignetting},
          {"pulse_jitter", c.options.pulse_jitter},
          {"pulse_b_energy", c.options.pulse_b_energy},
          {"noise", c.options.noise},
          {"liquid", c.optics.liquid.name},
          {"led", {{"peak_nm", c.optics.spectrum.peak_nm}, {"fwhm_nm", c.optics.spectrum.fwhm_nm}}},
          {"volume_mm",
           {{c.volume_min.x, c.volume_min.y, c.volume_min.z}, {c.volume_max.x, c.volume_max.y, c.volume_max.z}}},
          {"cameras", spray_cameras_json(c)},
          {"visible", "visible_mask bit c: the droplet's own shadow at pulse A reaches camera c's threshold 1 - 2 noise"},
          {"optics_setup_toml", spray_optics_setup_toml(c)}};
}

storage::SessionTruth spray_truth(const sim::SprayCase& c, const std::string& flow_name, const nlohmann::json& parameters) {
  storage::SessionTruth truth;
  truth.case_name = c.name;
  truth.flow_name = flow_name;
  truth.flow_parameters = parameters.dump();
  truth.seed = c.options.seed;
  for (const sim::SprayCamera& cam : c.cameras)
    truth.cameras.push_back(truth_camera_of(cam.id, cam.pinhole, cam.width, cam.height));
  return truth;
}

storage::SessionWriter open_spray_writer(const std::filesystem::path& out, const sim::SprayCase& c,
                                         storage::Compression compression, bool overwrite, const std::string& comment) {
  storage::SessionInfo info;
  for (const sim::SprayCamera& cam : c.cameras)
    info.cameras.push_back({cam.id, cam.width, cam.height, PixelFormat::Mono16, cam.pixel_pitch_um});
  info.rig_config_toml = comment;
  info.software_version = std::string(software_version());
  info.compression = compression;
  storage::SessionWriterOptions wo;
  wo.compression = compression;
  wo.overwrite = overwrite;
  return storage::SessionWriter(out, info, wo);
}

std::string write_spray_target_session(const sim::SprayOptions& options, const std::filesystem::path& out,
                                       storage::Compression compression, bool overwrite) {
  storage::check_output_path(out, overwrite, "session");
  const auto start = std::chrono::steady_clock::now();
  const sim::SprayCase c = sim::make_spray_thesis_case(options);
  const std::vector<optics::ChiSample>& depths = c.cameras.front().chi;
  nlohmann::json planes = nlohmann::json::array();
  for (std::size_t k = 0; k < depths.size(); ++k) planes.push_back({{"set", k}, {"z_mm", depths[k].z_mm}});
  const nlohmann::json parameters = {{"target", "chessboard: 2 mm squares, clear and chromium (5 %), turned 3 deg"},
                                     {"planes", planes},
                                     {"reduced", c.options.reduced},
                                     {"cameras", spray_cameras_json(c)},
                                     {"optics_setup_toml", spray_optics_setup_toml(c)}};
  storage::SessionWriter writer = open_spray_writer(
      out, c, compression, overwrite,
      "# Written by `tomorig simulate --case spray-thesis --targets`: set k shows a chessboard photomask at\n"
      "# depth k (planes[k].z_mm in /truth flow_parameters), for `tomorig optics psf`. No rig config applies.\n");
  writer.write_truth(spray_truth(c, "traverse", parameters));
  for (std::size_t k = 0; k < depths.size(); ++k) {
    FrameSet set;
    set.set_index = k;
    set.trigger_index = k;
    for (std::size_t ci = 0; ci < c.cameras.size(); ++ci) {
      CameraFrames frames;
      frames.camera_id = c.cameras[ci].id;
      frames.a.image = sim::render_spray_chessboard_target(c, ci, depths[k].z_mm, k);
      set.cameras.push_back(std::move(frames));
    }
    writer.append(set);
    writer.write_truth_set(k, {});
  }
  writer.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fmt::format("wrote {}: spray-thesis targets{}, {} depths x {} cameras, {} x {} px, seed {}, {:.1f} s", out.string(),
                     c.options.reduced ? " (reduced)" : "", depths.size(), c.cameras.size(), c.cameras[0].width,
                     c.cameras[0].height, c.options.seed, seconds);
}

std::string write_spray_session(const sim::SprayOptions& options, int sets, const std::filesystem::path& out,
                                storage::Compression compression, bool overwrite,
                                const std::function<void(int, int)>& progress) {
  if (sets < 1) throw bad_input(fmt::format("--sets {} is invalid: it must be >= 1", sets));
  storage::check_output_path(out, overwrite, "session");
  const auto start = std::chrono::steady_clock::now();
  const sim::SprayCase c = sim::make_spray_thesis_case(options);

  // The truth JSON holds every droplet, so the sets are rendered before the file is written.
  std::vector<sim::SpraySet> rendered;
  nlohmann::json set_truth = nlohmann::json::array();
  for (int k = 0; k < sets; ++k) {
    sim::SpraySet s = sim::render_spray_set(c, static_cast<std::uint64_t>(k));
    nlohmann::json d = nlohmann::json::array(), visible = nlohmann::json::array(), imin = nlohmann::json::array();
    for (const sim::Droplet& drop : s.droplets) {
      d.push_back(std::round(drop.d_um * 1000.0) / 1000.0);
      int mask = 0;
      nlohmann::json m = nlohmann::json::array();
      for (std::size_t ci = 0; ci < drop.visible.size(); ++ci) {
        if (drop.visible[ci]) mask |= 1 << ci;
        m.push_back(std::round(drop.min_intensity[ci] * 1e5) / 1e5);
      }
      visible.push_back(mask);
      imin.push_back(m);
    }
    set_truth.push_back({{"set", k},
                         {"d_um", d},
                         {"visible_mask", visible},
                         {"min_intensity", imin},
                         {"pulse_energy_a", s.pulse_energy_a},
                         {"pulse_energy_b", s.pulse_energy_b}});
    rendered.push_back(std::move(s));
    if (progress) progress(k + 1, sets);
  }
  // The truth's JSON is an HDF5 attribute, which holds at most 64 KiB: the per-set records go
  // in while they fit (800 reduced droplets take ~35 kB a set; a full-size set does not fit).
  // Any set's droplets, sizes included, are regenerated by sim::spray_droplets(case, k).
  constexpr std::size_t kTruthBudget = 60'000;
  nlohmann::json truth_json = spray_parameters_json(c);
  std::size_t size = truth_json.dump().size();
  nlohmann::json recorded = nlohmann::json::array();
  for (nlohmann::json& record : set_truth) {
    const std::size_t record_size = record.dump().size() + 1;
    if (size + record_size > kTruthBudget) break;
    size += record_size;
    recorded.push_back(std::move(record));
  }
  truth_json["sets_recorded"] = recorded.size();
  truth_json["sets"] = std::move(recorded);

  // The session holds the rig that records the same case live, so `tomorig process` and the other
  // back-end commands take it as they take a recorded one.
  std::string rig_toml = spray_rig_config_toml(c, sets);
  config::parse_rig_config(rig_toml, "spray-thesis rig");  // a bug here must not reach the file
  storage::SessionWriter writer = open_spray_writer(out, c, compression, overwrite, rig_toml);
  writer.write_truth(spray_truth(c, sim::to_string(c.options.pattern), truth_json));
  for (int k = 0; k < sets; ++k) {
    sim::SpraySet& s = rendered[static_cast<std::size_t>(k)];
    s.frames.trigger_timestamp_ns = static_cast<std::int64_t>(k) * 40'000'000;  // 25 Hz (Sect. 7.3)
    for (CameraFrames& cf : s.frames.cameras) {
      cf.a.timestamp_ns += s.frames.trigger_timestamp_ns;
      cf.b.timestamp_ns += s.frames.trigger_timestamp_ns;
    }
    writer.append(s.frames);
    storage::TruthSet ts;
    for (const sim::Droplet& d : s.droplets) {
      ts.particles_a.push_back(d.a);
      ts.particles_b.push_back(d.b);
    }
    writer.write_truth_set(static_cast<std::uint64_t>(k), ts);
  }
  writer.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fmt::format("wrote {}: spray-thesis{} ({}), {} sets x {} cameras, {} x {} px, {} droplets per set, seed {}, "
                     "{:.1f} s",
                     out.string(), c.options.reduced ? " (reduced)" : "", sim::to_string(c.options.pattern), sets,
                     c.cameras.size(), c.cameras[0].width, c.cameras[0].height, c.options.droplets, c.options.seed,
                     seconds);
}

sim::SprayPattern sim_spray_pattern(config::SprayPattern pattern) {
  switch (pattern) {
    case config::SprayPattern::jet_in_crossflow: return sim::SprayPattern::jet_in_crossflow;
    case config::SprayPattern::hollow_cone: return sim::SprayPattern::hollow_cone;
  }
  return sim::SprayPattern::jet_in_crossflow;
}

sim::SprayPattern parse_spray_pattern(const std::string& word, const std::string& option) {
  if (const auto pattern = config::parse<config::SprayPattern>(word)) return sim_spray_pattern(*pattern);
  throw bad_input(fmt::format("{} {}: unknown spray pattern, use one of {}", option, word,
                              config::allowed_words<config::SprayPattern>()));
}

}  // namespace tomorig::rig
