#pragma once
// Decoding a parsed TOML document into a RigConfig, one section per file. Each decoder reads
// its keys through a TableReader (which records type, range and unknown-key issues) and adds
// the cross-key checks of its section. Values that fail keep their defaults; the caller
// throws if any issue was recorded, so a half-valid RigConfig never escapes.
#include <optional>
#include <vector>

#include <toml++/toml.h>

#include "tomorig/config/rig_config.h"
#include "toml_reader.h"

namespace tomorig::config::detail {

RigConfig decode_rig(const toml::table& root, std::vector<ConfigIssue>& issues);

// [[cameras]]; after [trigger], whose camera timing frame_mode and features are checked against.
void decode_cameras(TableReader& root, const TriggerConfig& trigger, std::vector<CameraConfig>& cameras);
void decode_trigger(TableReader& root, TriggerConfig& trigger);                  // [trigger]
void decode_grid(TableReader& root, GridConfig& grid);                           // [grid]
void decode_processing(TableReader& root, ProcessingConfig& processing);         // [processing]
void decode_simulation(TableReader& root, std::optional<SimulationConfig>& sim);  // [simulation]
void decode_quicklook(TableReader& root, QuickLookConfig& quicklook);            // [quicklook] and sub-tables
void decode_dashboard(TableReader& root, DashboardConfig& dashboard);           // [dashboard]

// Parts of [trigger], called by decode_trigger() in this order.
void decode_camera_timing(TableReader& trigger, CameraTimingConfig& camera);  // [trigger.camera]
// [[trigger.light_sources]]; `trigger` holds the already-decoded pulse width (every source's
// default) and dt (`dt_ok`: usable for the cross-check).
void decode_light_sources(TableReader& trigger, const TriggerConfig& t, bool dt_ok,
                          std::vector<LightSourceConfig>& sources);
// [[trigger.channels]]; light sources must be decoded first (channels name them).
void decode_trigger_channels(TableReader& trigger, bool gpio, const std::vector<LightSourceConfig>& sources,
                             std::vector<TriggerChannel>& channels);

}  // namespace tomorig::config::detail
