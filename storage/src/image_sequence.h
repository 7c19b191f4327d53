#pragma once
// Finding the files of an image sequence and ordering them the way people number them.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace tomorig::storage {

// "im2.tif" < "im10.tif": runs of digits compare by value, everything else byte by byte.
bool natural_less(std::string_view a, std::string_view b);

// Regular files matching a glob pattern (*, ?, [...], ~), in natural order. Throws bad_input
// naming the camera and pattern if nothing matches.
std::vector<std::filesystem::path> find_sequence_files(const std::string& pattern, const std::string& camera_id);

}  // namespace tomorig::storage
