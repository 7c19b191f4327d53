#pragma once
#include <string_view>

namespace tomorig {
// "0.1.0" or "0.1.0+g<commit>" when built from a git checkout.
std::string_view software_version();
}  // namespace tomorig
