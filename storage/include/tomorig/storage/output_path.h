#pragma once
// Checks made before a writer creates anything, so that a bad output path fails at once with
// a message naming the path, and never after minutes of work. Commands whose output is not an
// HDF5 file of storage (a calibration file) call it before their work starts, too.
#include <filesystem>
#include <string_view>

namespace tomorig::storage {

// Throws tomorig::Error (bad_input) if `path` is a folder, exists and `overwrite` is false, or
// its folder is missing or not a folder. `kind` names the file in messages ("session").
void check_output_path(const std::filesystem::path& path, bool overwrite, std::string_view kind);

}  // namespace tomorig::storage
