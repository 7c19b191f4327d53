#pragma once
// JSON form of the quick-look results, for the preview stream and the session file:
//   nlohmann::json j = camera_quick_look;   // or frame statistics, a Δt check result, ...
// Figures that could not be measured (NaN) are null; flags are "green", "amber" or "red".
// docs/quicklook.md lists the fields.
#include <nlohmann/json_fwd.hpp>

#include "tomorig/processing/quicklook/drift_monitor.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/processing/quicklook/shadow_look.h"
#include "tomorig/processing/quicklook/statistics.h"

namespace tomorig::quicklook {

void to_json(nlohmann::json& j, Flag flag);
void to_json(nlohmann::json& j, const Judged& judged);
void to_json(nlohmann::json& j, const TileMap& map);
void to_json(nlohmann::json& j, const FrameStatistics& s);
void to_json(nlohmann::json& j, const CameraQuickLook& s);
void to_json(nlohmann::json& j, const DtCheckResult& r);
void to_json(nlohmann::json& j, const ShadowFrame& s);
void to_json(nlohmann::json& j, const ShadowCameraLook& s);
void to_json(nlohmann::json& j, const DriftReport& r);
void to_json(nlohmann::json& j, const SheetProfile& s);
// The numbers of a preview (grid, sheet, profile, timings); the volume and projections are not
// JSON (the preview stream sends the projections as images).
void to_json(nlohmann::json& j, const PreviewResult& r);

}  // namespace tomorig::quicklook
