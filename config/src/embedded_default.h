#pragma once
// The text of config/default-rig.toml, compiled in by config/CMakeLists.txt (the definition is
// generated into the build directory), so the file in the repository is the one source.
#include <string>

namespace tomorig::config::detail {
const std::string& embedded_default_rig_toml();
}  // namespace tomorig::config::detail
