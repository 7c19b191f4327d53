#pragma once
// What the quick-look stage runs with: the quick-look library's options (statistics, Δt check,
// drift monitor, preview volume, spray quick-look), each starting from the library's own default and overridden
// by the rig file's [quicklook] keys (config::QuickLookConfig, docs/configuration.md), then by
// the stage's own keys (`--stage quicklook:key=value`).
#include <string>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/processing/quicklook/drift_monitor.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/processing/quicklook/shadow_look.h"
#include "tomorig/processing/quicklook/statistics.h"

namespace tomorig::pipeline {

struct QuickLookSettings {
  quicklook::QuickLookOptions statistics;
  quicklook::DtCheckOptions dt_check;
  quicklook::DriftOptions drift;
  quicklook::PreviewVolumeOptions preview;
  quicklook::ShadowLookOptions shadow;  // the spray quick-look (shadow mode); bit_depth per camera
  bool preview_enabled = true;  // the preview volume and the drift monitor (they need cameras and a grid)
  bool store = true;            // quick-look numbers into the session file, when the recording has one
  std::string publish;          // PUB endpoint for the results; empty: none
  int thumbnail_px = 160;       // longest side of the camera thumbnails on the stream
  // Nice values (0 to 19) of the stage's threads, so that they yield the CPU to the recorder
  // (nice 0): the statistics of every set before the preview volume, which may skip sets.
  int nice = 5;                 // the statistics and Δt check thread
  int preview_nice = 10;        // the preview volume and drift monitor thread
};

// The library defaults with the rig file's [quicklook] keys applied (rig may be null: the
// defaults). Throws tomorig::Error (bad_input) naming the rig key when a value the rig file
// could not check on its own is out of the library's range.
QuickLookSettings quicklook_settings(const config::RigConfig* rig);

// `--preview [ENDPOINT]` as given (no value or one): the endpoint to publish on, the default
// (stream::kDefaultPreviewEndpoint) when none was given.
std::string preview_endpoint(const std::vector<std::string>& given);
// The quick-look stage publishing on `endpoint`. Throws bad_input if `others` already hold a
// quicklook stage (two would publish twice).
StageSpec quicklook_stage_spec(const std::string& endpoint, const std::vector<StageSpec>& others);

// One line on what a quicklook stage did, from its StageReport::status: messages published and
// dropped for slow viewers, rows stored, preview volumes made and sets they passed over, alarms.
// Empty for a report that is not a quicklook stage's.
std::string quicklook_report_text(const StageReport& report);

}  // namespace tomorig::pipeline
