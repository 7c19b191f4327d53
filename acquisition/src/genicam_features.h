#pragma once
// Setting GenICam features by name with errors that name the camera and the feature.
#include <arv.h>

#include <string>
#include <vector>

namespace tomorig::acquisition::detail {

// Whether the camera's GenICam description has an implemented feature of this name.
bool has_feature(ArvDevice* device, const std::string& feature);
// ... and whether it can be written in the camera's current state.
bool feature_available(ArvDevice* device, const std::string& feature);

// Sets `feature` to `value` (an enumeration entry, a number, a boolean or a string).
// Throws bad_input "camera <camera_id>: ..." naming the feature when the camera lacks it,
// an enumeration does not offer the value (listing what it offers), a number is out of the
// camera's range, or the camera refuses or changes the value (read back after writing).
void set_feature(ArvDevice* device, const std::string& camera_id, const std::string& feature,
                 const std::string& value);

// Entries an enumeration feature currently offers (empty if it is not an enumeration).
std::vector<std::string> enumeration_entries(ArvDevice* device, const std::string& feature);

}  // namespace tomorig::acquisition::detail
