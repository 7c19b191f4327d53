#pragma once
// The images of one exposure of a recorded set, camera by camera, as a reconstruction takes
// them: reconstruct, reconstruct --mean and process all read a set this way.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/core/image.h"

namespace tomorig::pipeline {

// Throws bad_input naming the session, set, exposure and camera of a missing frame, followed by
// `advice` (what the caller's user can do instead).
std::vector<Image> exposure_images(const FrameSet& set, Exposure exposure, const std::string& session,
                                   std::uint64_t index, std::string_view advice);

}  // namespace tomorig::pipeline
