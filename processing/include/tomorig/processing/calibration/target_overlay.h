#pragma once
// A picture of what target detection found in one image, for the user to check it by eye
// (`tomorig calibrate --overlay DIR`): the image dimmed to grey, each identified point
// circled, the origin ringed and the world +x and +y axes drawn from it with their letters.
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {

// An 8-bit image of `image`'s size: the image scaled to 0..160 (1st to 99.9th percentile),
// marks in white (255) and black (0) so they show on any background.
Image draw_detection_overlay(const Image& image, const TargetDetection& detection);

}  // namespace tomorig::calibration
