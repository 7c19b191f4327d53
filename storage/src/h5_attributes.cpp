#include "h5_attributes.h"

#include <algorithm>
#include <string>

#include "h5_error.h"
#include "h5_handle.h"
#include "h5_strings.h"

namespace tomorig::storage::h5 {
namespace {

std::string attr_name(const char* name, std::string_view where) {
  return "attribute '" + std::string(name) + "' of " + std::string(where);
}

void write_attr(hid_t object, const char* name, hid_t file_type, hid_t space, hid_t mem_type, const void* data,
                std::string_view where) {
  const std::string what = attr_name(name, where);
  Attribute attr(check(H5Acreate2(object, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT), "cannot create", what));
  check(H5Awrite(attr.get(), mem_type, data), "cannot write", what);
}

void write_scalar(hid_t object, const char* name, hid_t file_type, hid_t mem_type, const void* data,
                  std::string_view where) {
  Dataspace space(check(H5Screate(H5S_SCALAR), "cannot create", attr_name(name, where)));
  write_attr(object, name, file_type, space.get(), mem_type, data, where);
}

Attribute open_attr(hid_t object, const char* name, std::string_view where) {
  if (H5Aexists(object, name) <= 0) throw Failure(attr_name(name, where) + " is missing");
  return Attribute(check(H5Aopen(object, name, H5P_DEFAULT), "cannot open", attr_name(name, where)));
}

std::size_t element_count(hid_t attr, const std::string& what) {
  Dataspace space(check(H5Aget_space(attr), "cannot read the shape of", what));
  return static_cast<std::size_t>(check(H5Sget_simple_extent_npoints(space.get()), "cannot read the shape of", what));
}

// Reads a one-element numeric attribute converted to `mem_type`; `integer` refuses floats.
void read_scalar(hid_t object, const char* name, hid_t mem_type, void* out, std::string_view where,
                 bool integer = false) {
  const std::string what = attr_name(name, where);
  Attribute attr = open_attr(object, name, where);
  Datatype stored(check(H5Aget_type(attr.get()), "cannot read the type of", what));
  const H5T_class_t cls = H5Tget_class(stored.get());
  if (cls != H5T_INTEGER && cls != H5T_FLOAT) throw Failure(what + " is not a number");
  if (integer && cls != H5T_INTEGER) throw Failure(what + " is a floating-point number; an integer is expected");
  if (element_count(attr.get(), what) != 1) throw Failure(what + " holds more than one value");
  check(H5Aread(attr.get(), mem_type, out), "cannot read", what);
}

}  // namespace

void write_string_attr(hid_t object, const char* name, std::string_view value, std::string_view where) {
  Datatype type = utf8_string_type();
  const std::string copy(value);  // NUL-terminated for HDF5
  const char* pointer = copy.c_str();
  write_scalar(object, name, type.get(), type.get(), &pointer, where);
}

void write_string_list_attr(hid_t object, const char* name, const std::vector<std::string>& values,
                            std::string_view where) {
  Datatype type = utf8_string_type();
  std::vector<const char*> pointers;
  pointers.reserve(values.size());
  for (const auto& v : values) pointers.push_back(v.c_str());
  const hsize_t dims[1] = {values.size()};
  Dataspace space(check(H5Screate_simple(1, dims, nullptr), "cannot create", attr_name(name, where)));
  // An empty list still needs a non-null buffer: HDF5 refuses a null one even for 0 elements.
  const char* none = nullptr;
  write_attr(object, name, type.get(), space.get(), type.get(), values.empty() ? &none : pointers.data(), where);
}

void write_fixed_string_attr(hid_t object, const char* name, std::string_view value, std::string_view where) {
  Datatype type = fixed_utf8_string_type(value.size());
  std::string padded(value);
  padded.resize(H5Tget_size(type.get()), '\0');
  write_scalar(object, name, type.get(), type.get(), padded.data(), where);
}

void write_fixed_string_list_attr(hid_t object, const char* name, const std::vector<std::string>& values,
                                  std::string_view where) {
  std::size_t longest = 1;
  for (const auto& v : values) longest = std::max(longest, v.size());
  Datatype type = fixed_utf8_string_type(longest);
  std::vector<char> packed(longest * std::max<std::size_t>(values.size(), 1), '\0');
  for (std::size_t i = 0; i < values.size(); ++i) std::copy(values[i].begin(), values[i].end(), packed.begin() + i * longest);
  const hsize_t dims[1] = {values.size()};
  Dataspace space(check(H5Screate_simple(1, dims, nullptr), "cannot create", attr_name(name, where)));
  write_attr(object, name, type.get(), space.get(), type.get(), packed.data(), where);
}

void write_int_attr(hid_t object, const char* name, std::int64_t value, hid_t file_type, std::string_view where) {
  write_scalar(object, name, file_type, H5T_NATIVE_INT64, &value, where);
}

void write_uint64_attr(hid_t object, const char* name, std::uint64_t value, std::string_view where) {
  write_scalar(object, name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &value, where);
}

void write_double_attr(hid_t object, const char* name, double value, std::string_view where) {
  write_scalar(object, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value, where);
}

void write_doubles_attr(hid_t object, const char* name, std::span<const double> values,
                        std::span<const hsize_t> dims, std::string_view where) {
  Dataspace space(check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "cannot create",
                        attr_name(name, where)));
  write_attr(object, name, H5T_IEEE_F64LE, space.get(), H5T_NATIVE_DOUBLE, values.data(), where);
}

void write_int32s_attr(hid_t object, const char* name, std::span<const std::int32_t> values,
                       std::span<const hsize_t> dims, std::string_view where) {
  Dataspace space(check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "cannot create",
                        attr_name(name, where)));
  write_attr(object, name, H5T_STD_I32LE, space.get(), H5T_NATIVE_INT32, values.data(), where);
}

bool has_attr(hid_t object, const char* name) { return H5Aexists(object, name) > 0; }

std::string read_string_attr(hid_t object, const char* name, std::string_view where) {
  const std::string what = attr_name(name, where);
  Attribute attr = open_attr(object, name, where);
  auto values = read_strings(attr.get(), StringSource::attribute, what);
  if (values.size() != 1) throw Failure(what + " should hold one string but holds " + std::to_string(values.size()));
  return std::move(values.front());
}

std::vector<std::string> read_string_list_attr(hid_t object, const char* name, std::string_view where) {
  Attribute attr = open_attr(object, name, where);
  return read_strings(attr.get(), StringSource::attribute, attr_name(name, where));
}

std::int64_t read_int_attr(hid_t object, const char* name, std::string_view where) {
  std::int64_t value = 0;
  read_scalar(object, name, H5T_NATIVE_INT64, &value, where, true);
  return value;
}

std::uint64_t read_uint64_attr(hid_t object, const char* name, std::string_view where) {
  std::uint64_t value = 0;
  read_scalar(object, name, H5T_NATIVE_UINT64, &value, where, true);
  return value;
}

double read_double_attr(hid_t object, const char* name, std::string_view where) {
  double value = 0;
  read_scalar(object, name, H5T_NATIVE_DOUBLE, &value, where);
  return value;
}

std::vector<double> read_doubles_attr(hid_t object, const char* name, std::size_t count, std::string_view where) {
  const std::string what = attr_name(name, where);
  Attribute attr = open_attr(object, name, where);
  const std::size_t n = element_count(attr.get(), what);
  if (n != count)
    throw Failure(what + " should hold " + std::to_string(count) + " values but holds " + std::to_string(n));
  std::vector<double> values(n);
  check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()), "cannot read", what);
  return values;
}

}  // namespace tomorig::storage::h5
