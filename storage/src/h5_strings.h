#pragma once
// The string datatypes of the session layout, shared by attributes and datasets.
#include <hdf5.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "h5_handle.h"

namespace tomorig::storage::h5 {

// Variable-length UTF-8 string type: what results and volume files (and session files of
// format version 1) hold.
Datatype utf8_string_type();
// Fixed-length UTF-8 string type of `bytes` bytes (at least 1), padded with NULs: what session
// files of format version 2 hold. Unlike variable-length strings, whose bytes live in a global
// heap that libhdf5 1.10 reads without bounds checks, these are read straight from the object.
Datatype fixed_utf8_string_type(std::size_t bytes);

// The most bytes the strings of one attribute or dataset may take in memory (fixed-length
// bytes, or one pointer per variable-length string). tomorig's strings are metadata: ids, the
// rig file, JSON parameters and reports, far below this; a damaged file may declare more.
inline constexpr std::size_t kMaxStringBytes = std::size_t{256} << 20;

// All strings held by an open attribute or dataset (`source` says which), whether stored
// as variable- or fixed-length strings; HDF5's variable-length buffers are freed here. Throws
// Failure for a non-string type and for more than kMaxStringBytes, before allocating anything.
enum class StringSource { attribute, dataset };
std::vector<std::string> read_strings(hid_t object, StringSource source, std::string_view where);

}  // namespace tomorig::storage::h5
