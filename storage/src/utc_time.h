#pragma once
#include <string>

namespace tomorig::storage {
// The current time as ISO 8601 UTC with second resolution, e.g. "2024-05-01T12:34:56Z".
std::string utc_now_iso8601();
}  // namespace tomorig::storage
