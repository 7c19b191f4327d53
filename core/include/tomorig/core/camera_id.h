#pragma once
// The one rule for camera ids. An id becomes an HDF5 group name (/cameras/<id>), part of file
// names (<id>_set0_A.png), a wire-protocol field and text on a terminal, so it is checked the
// same way wherever it enters: the rig file (config/), the wire (stream/) and session files
// (storage/). A valid id is 1 to kMaxCameraIdBytes bytes of UTF-8 without control characters
// (NUL, escape, ... U+0000-U+001F, U+007F-U+009F), without '/', and is not "." or "..".
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace tomorig {

inline constexpr std::size_t kMaxCameraIdBytes = 128;

// Nothing if `id` is a valid camera id; otherwise what is wrong, e.g. "contains '/'".
std::optional<std::string> camera_id_problem(std::string_view id);

// `text` safe to print in a message: printable ASCII as is, every other byte as \xNN, and cut
// (with "...") after 64 bytes, so that a hostile id cannot send escape sequences to a terminal.
std::string printable(std::string_view text);

// Throws tomorig::Error (bad_input): "<context>: camera id "<printable id>" is not allowed: <why>".
void require_valid_camera_id(std::string_view id, std::string_view context);

}  // namespace tomorig
