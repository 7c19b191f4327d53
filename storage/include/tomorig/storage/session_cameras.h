#pragma once
// The checks a session's camera list must pass, for callers that must know before creating a
// file (a recorder learning its cameras from a stream).
#include <filesystem>
#include <vector>

#include "tomorig/storage/session_file.h"

namespace tomorig::storage {

// The checks SessionWriter's constructor makes of a camera list before it touches any file
// (count at most 256, ids by core/camera_id.h and unique, sizes 1 to 65536, one frame within an
// HDF5 chunk). Throws tomorig::Error (bad_input) naming `file` and the camera.
void check_session_cameras(const std::vector<SessionCamera>& cameras, const std::filesystem::path& file);

}  // namespace tomorig::storage
