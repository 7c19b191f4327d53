#pragma once
// A recorded session on the dashboard (`tomorig preview --session S.h5 --http`): its stored
// quick-look history (/quicklook, docs/file-formats.md) as time series, with the trigger plan
// of the rig it was taken with.
#include <optional>

#include "tomorig/config/rig_config.h"
#include "tomorig/dashboard/dashboard_state.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::dashboard {

// Sets the state's info (mode "session") and history. bad_input naming the file when it holds
// no quick-look numbers (recorded without --preview or a quicklook stage).
// The rig a session was taken with, for the trigger plan and the targets; none for a session
// imported from elsewhere or one whose rig file this release cannot read.
std::optional<config::RigConfig> session_rig(const storage::SessionReader& session);

void show_session(DashboardState& state, const storage::SessionReader& session);

}  // namespace tomorig::dashboard
