#pragma once
// The dashboard's "info" topic: where the figures come from, the rig's trigger plan and the
// quick-look targets the gauges draw their green and amber bands from.
#include <string>

#include <nlohmann/json.hpp>

#include "tomorig/config/rig_config.h"

namespace tomorig::dashboard {

struct InfoSource {
  std::string mode = "live";  // "live" (a run, a replay) or "session" (a recorded file)
  std::string source;         // the endpoint or the file, for the title
  const config::RigConfig* rig = nullptr;  // null: no trigger plan, the library's targets
  bool snapshots = false;     // POST /api/snapshot writes files
};

// {"mode", "source", "rig", "snapshots", "trigger_plan": {"rate_hz", "dt_us", "text"} or
// {"error"} or null, "targets": {figure: {"low", "high", "amber"}}}.
nlohmann::json dashboard_info(const InfoSource& source);

}  // namespace tomorig::dashboard
