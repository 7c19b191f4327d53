#pragma once
// Reading and writing HDF5 attributes with the file types the session layout documents
// (docs/file-formats.md). `where` names the object ("/cameras/cam0") in error messages.
// Strings are written as variable-length UTF-8 (h5py returns str, MATLAB's h5readatt char) or,
// for session files, as fixed-length UTF-8 (h5py returns bytes); the readers accept both.
#include <hdf5.h>

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace tomorig::storage::h5 {

void write_string_attr(hid_t object, const char* name, std::string_view value, std::string_view where);
void write_string_list_attr(hid_t object, const char* name, const std::vector<std::string>& values,
                            std::string_view where);
// The same as fixed-length strings (see fixed_utf8_string_type), sized to the longest value.
void write_fixed_string_attr(hid_t object, const char* name, std::string_view value, std::string_view where);
void write_fixed_string_list_attr(hid_t object, const char* name, const std::vector<std::string>& values,
                                  std::string_view where);
// `file_type` is the integer type stored in the file, e.g. H5T_STD_I32LE.
void write_int_attr(hid_t object, const char* name, std::int64_t value, hid_t file_type, std::string_view where);
void write_uint64_attr(hid_t object, const char* name, std::uint64_t value, std::string_view where);
void write_double_attr(hid_t object, const char* name, double value, std::string_view where);
// A float64 array attribute of shape `dims` (e.g. {3, 3}), values in row-major order.
void write_doubles_attr(hid_t object, const char* name, std::span<const double> values,
                        std::span<const hsize_t> dims, std::string_view where);

// An int32 array attribute (counts such as a grid's nodes: h5py gives an integer array, so
// `reshape(nz, ny, nx, 3)` takes it as is).
void write_int32s_attr(hid_t object, const char* name, std::span<const std::int32_t> values,
                       std::span<const hsize_t> dims, std::string_view where);

bool has_attr(hid_t object, const char* name);
// The readers throw h5::Failure naming the attribute and object when it is missing or has
// the wrong class or size; numeric values are converted by HDF5 from whatever type is stored,
// except that the integer readers refuse a floating-point attribute (a stored 1.5 is not a
// count or a version).
std::string read_string_attr(hid_t object, const char* name, std::string_view where);
std::vector<std::string> read_string_list_attr(hid_t object, const char* name, std::string_view where);
std::int64_t read_int_attr(hid_t object, const char* name, std::string_view where);
std::uint64_t read_uint64_attr(hid_t object, const char* name, std::string_view where);
double read_double_attr(hid_t object, const char* name, std::string_view where);
// All values, flattened in row-major order; throws unless there are exactly `count`.
std::vector<double> read_doubles_attr(hid_t object, const char* name, std::size_t count, std::string_view where);

}  // namespace tomorig::storage::h5
