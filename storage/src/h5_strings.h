#pragma once
// The string datatypes of the session layout, shared by attributes and datasets.
#include <hdf5.h>

#include <string>
#include <string_view>
#include <vector>

#include "h5_handle.h"

namespace tomorig::storage::h5 {

// Variable-length UTF-8 string type, what tomorig writes.
Datatype utf8_string_type();

// All strings held by an open attribute or dataset (`source` says which), whether stored
// as variable- or fixed-length strings; HDF5's variable-length buffers are freed here.
enum class StringSource { attribute, dataset };
std::vector<std::string> read_strings(hid_t object, StringSource source, std::string_view where);

}  // namespace tomorig::storage::h5
