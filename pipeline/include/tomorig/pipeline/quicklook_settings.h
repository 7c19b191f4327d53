#pragma once
// What the quick-look stage runs with: the quick-look library's options (statistics, Δt check,
// drift monitor, preview volume), each starting from the library's own default and overridden
// by the rig file's [quicklook] keys (config::QuickLookConfig, docs/configuration.md), then by
// the stage's own keys (`--stage quicklook:key=value`).
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/processing/quicklook/drift_monitor.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/processing/quicklook/statistics.h"

namespace tomorig::pipeline {

struct QuickLookSettings {
  quicklook::QuickLookOptions statistics;
  quicklook::DtCheckOptions dt_check;
  quicklook::DriftOptions drift;
  quicklook::PreviewVolumeOptions preview;
  bool preview_enabled = true;  // the preview volume and the drift monitor (they need cameras and a grid)
  bool store = true;            // quick-look numbers into the session file, when the recording has one
  std::string publish;          // PUB endpoint for the results; empty: none
  int thumbnail_px = 160;       // longest side of the camera thumbnails on the stream
};

// The library defaults with the rig file's [quicklook] keys applied (rig may be null: the
// defaults). Throws tomorig::Error (bad_input) naming the rig key when a value the rig file
// could not check on its own is out of the library's range.
QuickLookSettings quicklook_settings(const config::RigConfig* rig);

}  // namespace tomorig::pipeline
