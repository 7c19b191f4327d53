#pragma once
// Compression filters for frame datasets. bitshuffle-LZ4 is not built into HDF5: it is a
// dynamically loaded filter plugin (Debian package "bitshuffle", installed into HDF5's plugin
// folder), so its presence is checked before writing and before reading.
#include <hdf5.h>

#include <string>

#include "tomorig/storage/session_file.h"

namespace tomorig::storage {

// Registered HDF5 filter id of bitshuffle (https://github.com/HDFGroup/hdf5_plugins).
inline constexpr H5Z_filter_t kBitshuffleFilterId = 32008;
// Filter options: block size 0 (chosen by bitshuffle), 2 = LZ4 after the bit shuffle. The
// plugin prepends its version and the element size when the dataset is created.
inline constexpr unsigned kBitshuffleBlockSizeAuto = 0;
inline constexpr unsigned kBitshuffleLz4 = 2;

// Throws tomorig::Error (runtime) naming the filter and the package that provides it when
// `filter` cannot be loaded. `purpose` says what needed it ("writing session 'x.h5'").
void require_filter(H5Z_filter_t filter, const std::string& purpose);

// Adds the filter for `compression` to a dataset-creation property list (after checking
// that it is available).
void add_compression_filter(hid_t dcpl, Compression compression, const std::string& purpose);

}  // namespace tomorig::storage
