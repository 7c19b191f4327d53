#pragma once
// The rig configuration: cameras, trigger, calibration, voxel grid, processing and the
// simulated scene. Parsed from TOML by load_rig_config(); every value is validated and every
// error names the key path and line. toml++ stays inside config/src.
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "tomorig/config/rig_vocabulary.h"
#include "tomorig/core/pixel_format.h"

namespace tomorig::config {

struct Roi {
  int offset_x = 0, offset_y = 0;
  int width = 0, height = 0;  // pixels; 0 x 0: the full sensor (Aravis camera without [cameras.roi])
};

struct CameraConfig {
  std::string id;                               // unique, e.g. "cam0"
  CameraBackend backend = CameraBackend::simulated;
  std::string device_id;                        // Aravis device id; gentl: the GenTL device id, serial
                                                // or user-defined name; for simulated: the view name
  // gentl only: the producer (.cti file); empty: the producers GENICAM_GENTL64_PATH names.
  std::filesystem::path producer;
  std::map<std::string, std::string> features;  // extra GenICam features, applied verbatim
  Roi roi;
  PixelFormat pixel_format = PixelFormat::Mono16;
  double pixel_pitch_um = 7.4;
  FrameMode frame_mode = FrameMode::hardware;
  // Simulated cameras only: pinhole placement (see simulators/).
  double yaw_deg = 0.0;
  double focal_length_mm = 100.0;
  double distance_mm = 263.16;
};

// A light source the trigger fires ([[trigger.light_sources]]). Its safety limits are
// enforced by the trigger device; unset limits take the trigger module's built-in defaults
// for the kind (docs/trigger.md).
struct LightSourceConfig {
  std::string name;                 // unique, e.g. "laser1", "led_cam0"
  LightSourceKind kind = LightSourceKind::unknown;  // "laser" | "led"; unknown: not stated (strictest limits)
  double pulse_width_us = 0.01;     // optical pulse width; default: trigger.pulse_width_us
  double flashlamp_lead_us = 0.0;   // lasers: flash lamp -> Q-switch delay
  std::optional<double> max_pulse_width_us;  // safety limits; see docs/configuration.md for bounds
  std::optional<double> max_duty_cycle;
  std::optional<double> max_rate_hz;
};

struct TriggerChannel {
  std::string name;           // e.g. "laser1", "cam_trigger"
  ChannelRole role = ChannelRole::camera;  // required in the file: "light" | "camera" | "flashlamp" | "pulse_generator"
  std::string light_source;   // light and flashlamp channels: a LightSourceConfig::name; empty:
                              // (light, no [[trigger.light_sources]]) the channel is its own source
  PulseSelect pulses = PulseSelect::both;  // light and flashlamp channels: "first" | "second" | "both"
  double delay_us = 0.0;      // edge -> effect: camera latency, LED rise time, Q-switch build-up
  std::optional<double> width_us;  // electrical pulse width; unset: the trigger module's default
  std::string chip;           // GPIO chip for the gpio backend, e.g. "gpiochip0"
  int line = -1;              // GPIO line offset
};

// The double-frame camera timing ([trigger.camera]); all cameras alike.
struct CameraTimingConfig {
  double exposure_a_us = 20.0;    // frame A exposure
  double interframe_us = 0.12;    // blind time between frames A and B
  double exposure_b_us = 1000.0;  // frame B (until frame A is read out)
  // frame_mode "two_triggers": the least time from the end of one exposure to the next
  // trigger the camera accepts (sensor readout); 0: not given (required for two_triggers).
  double readout_us = 0.0;
  // How far B - A of a camera's frame timestamps may stray from the plan; unset: half the
  // smaller of the frame separation and the rest of the period for two_triggers, no check
  // for hardware double-frame cameras (whose timestamps differ by vendor).
  std::optional<double> frame_time_tolerance_us;
};

struct TriggerConfig {
  TriggerBackend backend = TriggerBackend::simulated;
  double rate_hz = 10.0;          // repetition rate of double-frame events
  double dt_us = 100.0;           // pulse separation
  double pulse_width_us = 0.01;   // light pulse width (default of every light source)
  double jitter_ns = 0.0;         // simulated backend: timing jitter (1 sigma)
  double gpio_resolution_us = 1000.0;  // gpio backend: time resolution of a userspace GPIO edge
  CameraTimingConfig camera;
  std::vector<LightSourceConfig> light_sources;
  std::vector<TriggerChannel> channels;
};

struct GridConfig {
  int nx = 512, ny = 512, nz = 160;
  double voxel_size_mm = 0.0195;
  double origin_mm[3] = {0.0, 0.0, 0.0};  // world position of the grid centre
};

struct ProcessingConfig {
  // Absent (empty / 0): the reconstruction library's default (recon::ReconstructionOptions), so
  // each parameter has one default, in one place.
  std::string algorithm;  // reconstruction algorithm for `tomorig reconstruct`
  int iterations = 0;     // iterations of MART/SMART/FMART
};

struct SimulationConfig {
  std::string case_name = "tpiv-thesis";
  double ppp = 0.05;
  std::uint64_t seed = 1;
  int sets = 2;
  int bit_depth = 16;             // 12 or 16
  bool noise = false;             // shot + read noise
  double read_noise_e = 5.0;      // electrons, 1 sigma
  double peak_counts = 1000.0;    // peak intensity of a particle image
  LightSheetProfile light_sheet = LightSheetProfile::uniform;  // "uniform" | "gaussian" | "tophat"
  // spray-thesis only (docs/spray.md): the droplet pattern, and LED pulse B's energy relative
  // to pulse A (1: equal; 0.8: a 20 % drop, which the spray quick-look flags).
  SprayPattern spray = SprayPattern::jet_in_crossflow;  // "jet-in-crossflow" | "hollow-cone"
  double pulse_b_energy = 1.0;
};

// [quicklook], [quicklook.dt_check], [quicklook.drift], [quicklook.preview], [quicklook.spray]: the targets and
// settings of the quick-look stage (docs/quicklook.md). Every key is optional; an absent one
// keeps the quick-look library's own default (processing/quicklook), so each parameter has its
// default in one place. Ranges are [low, high] (green); amber bands stay the library's.
struct QuickLookConfig {
  std::optional<int> tile_px;
  std::optional<int> detail_tiles;  // tiles sampled for d_tau, autocovariance ppp and focus
  std::optional<double> peak_sigmas;
  std::optional<std::array<double, 2>> ppp, diameter_px, energy_balance;
  std::optional<double> source_density_max, saturated_fraction_max, soft_tile_fraction_max;

  struct DtCheck {
    std::optional<int> window_px;
    std::optional<std::array<int, 2>> windows;  // along x, y
    std::optional<double> min_peak_ratio;
    std::optional<std::array<double, 2>> displacement_px;
    std::optional<double> valid_fraction_min;
  } dt_check;

  struct Drift {
    std::optional<double> warn_px;
    std::optional<int> window_sets;
    std::optional<std::array<int, 3>> subvolumes;  // along x, y, z
    std::optional<double> search_radius_px;
  } drift;

  struct Preview {
    std::optional<std::string> algorithm;  // "mlos" | "ment"
    std::optional<int> binning;
    std::optional<double> depth_factor;
    std::optional<double> mlos_threshold;
    std::optional<int> ment_iterations;
  } preview;

  // The spray quick-look's targets and settings (shadowgraphy rigs, docs/spray.md).
  struct Spray {
    std::optional<double> coverage_max;              // shadow coverage, fraction of the view
    std::optional<double> uniformity_min;            // bright field p5 / p95
    std::optional<double> energy_tolerance;          // LED pulse energy: green within 1 +- this
    std::optional<std::array<double, 2>> bright_fraction;  // bright-field level, of full scale
    std::optional<std::array<double, 2>> shadow_count;     // droplet shadows per frame
    std::optional<double> min_intensity_max;         // the deepest shadow reaches at least this low
    std::optional<int> binning;                      // working image: 0 automatic, 1..8
    std::optional<double> shadow_sigmas;
    std::optional<int> reference_sets;
  } spray;
};

// [dashboard]: the operator's dashboard of `tomorig run --http` (docs/dashboard.md).
struct DashboardConfig {
  std::string http;           // HOST:PORT for --http given without a value; empty: the dashboard's default
  bool allow_remote = false;  // a non-loopback address is allowed (then every request needs a token)
};

struct RigConfig {
  std::string name = "tomorig rig";
  std::vector<CameraConfig> cameras;
  TriggerConfig trigger;
  std::optional<std::filesystem::path> calibration_file;
  GridConfig grid;
  ProcessingConfig processing;
  std::optional<SimulationConfig> simulation;
  QuickLookConfig quicklook;
  DashboardConfig dashboard;
  std::string source_text;  // the TOML text it was parsed from
};

// One problem found while validating: key path ("cameras[2].pixel_format"), line (0 if
// unknown) and the message saying what is allowed.
struct ConfigIssue {
  std::string key;
  int line = 0;
  std::string message;
  std::string origin;  // the file (or "<config>"); empty: left out of to_string()
  int column = 0;      // TOML syntax errors only (0: not shown)
  std::string to_string() const;  // "rig.toml:12: cameras[2].pixel_format: ..."
};

// Parses and validates. On any problem throws tomorig::Error (bad_input) whose message lists
// every issue, one per line. `origin` names the file in messages.
RigConfig parse_rig_config(const std::string& toml_text, const std::string& origin = "<config>");
RigConfig load_rig_config(const std::filesystem::path& path);
// Same checks, returning the issues instead of throwing (empty: valid).
std::vector<ConfigIssue> check_rig_config(const std::string& toml_text, const std::string& origin = "<config>");

// The embedded default: the simulated 4-camera tpiv-thesis rig.
const std::string& default_rig_toml();
RigConfig default_rig_config();

// The simulator's built-in cases ([simulation] case), as defined in ../shared/benchmarks.
const std::vector<std::string>& simulation_case_names();

// to_string / parse of the enums: rig_vocabulary.h.

}  // namespace tomorig::config
