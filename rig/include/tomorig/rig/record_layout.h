#pragma once
// What a recorder learns from the stream: a session file needs its camera list before the
// first set is written. A sender's session start announces it (sizes may be unknown until the
// first set); a stream without one (an older sender) lets the first set define it. Every later
// set must match it.
#include <optional>
#include <string>
#include <vector>

#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::rig {

// The cameras of `set` (ids, sizes, pixel formats: u8 -> Mono8, u16 -> Mono16), or nullopt
// with `why` set if the set cannot define a session (a camera without any frame, float
// samples, no cameras, A and B of different sizes).
std::optional<std::vector<storage::SessionCamera>> cameras_from_set(const FrameSet& set, std::string& why);

// The announced cameras with the image sizes the announcement left open (width and height 0)
// taken from `set`, which must have the announced ids in the announced order and the same
// sample types; nullopt with `why` otherwise (or if `set` cannot tell an open size). Pixel
// pitch and pixel format stay as announced (a Mono12 camera's frames arrive as 16-bit samples).
std::optional<std::vector<storage::SessionCamera>> complete_announced_cameras(
    const std::vector<storage::SessionCamera>& announced, const FrameSet& set, std::string& why);

// True if `set` has the same cameras, in the same order, and every present frame has that
// camera's size and sample type; otherwise false with `why` naming the first difference.
bool set_matches_cameras(const FrameSet& set, const std::vector<storage::SessionCamera>& cameras, std::string& why);

// Pixel bytes of the present frames (what reaches the disk before compression).
std::uint64_t pixel_bytes(const FrameSet& set);

}  // namespace tomorig::rig
