#pragma once
// What a session says about its rig besides the frames: `tomorig run` writes it into the
// session file, `tomorig acquire` sends it in the session start so `tomorig record` writes the
// same. One function, so the two files cannot differ.
#include "tomorig/rig/rig_acquisition.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

// Cameras (sizes 0 where the configuration leaves them open), the rig file's text and this
// program's version; the creation time is left to the writer.
storage::SessionInfo rig_session_info(const config::RigConfig& rig, const RigAcquisition& acquisition);

}  // namespace tomorig::rig
