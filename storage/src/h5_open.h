#pragma once
// Opening an HDF5 file for reading with errors a user can act on: a missing path, a folder,
// a file that is not HDF5, a file locked by a writer, a corrupt or truncated file. Shared by
// every reader in storage/, which differ only in what they call the file ("session file").
#include <filesystem>
#include <string_view>

#include "h5_handle.h"

namespace tomorig::storage::h5 {

// Metadata read attempts of a SWMR reader (see h5_open.cpp; HDF5's default is 100).
inline constexpr unsigned kSwmrReadAttempts = 24;

// Throws tomorig::Error (bad_input) naming `kind` ("session file", "volume file") and the path.
File open_for_reading(const std::filesystem::path& path, std::string_view kind);

}  // namespace tomorig::storage::h5
