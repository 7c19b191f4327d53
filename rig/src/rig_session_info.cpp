#include "tomorig/rig/rig_session_info.h"

#include <string>

#include "tomorig/core/version.h"

namespace tomorig::rig {

storage::SessionInfo rig_session_info(const config::RigConfig& rig, const RigAcquisition& acquisition) {
  storage::SessionInfo info;
  info.cameras = acquisition.session_cameras();
  info.rig_config_toml = rig.source_text;
  info.software_version = std::string(software_version());
  return info;
}

}  // namespace tomorig::rig
