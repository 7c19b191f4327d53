#include "tomorig/pipeline/exposure_images.h"

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::pipeline {

std::vector<Image> exposure_images(const FrameSet& set, Exposure exposure, const std::string& session,
                                   std::uint64_t index, std::string_view advice) {
  std::vector<Image> images;
  images.reserve(set.cameras.size());
  for (const CameraFrames& c : set.cameras) {
    const Frame& f = c[exposure];
    if (!f.present())
      throw bad_input(fmt::format("session '{}' set {}: frame {} of camera {} is missing; {}", session, index,
                                  exposure == Exposure::A ? "A" : "B", c.camera_id, advice));
    images.push_back(f.image);
  }
  return images;
}

}  // namespace tomorig::pipeline
