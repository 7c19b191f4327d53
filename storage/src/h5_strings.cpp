#include "h5_strings.h"

#include <cstring>
#include <memory>

#include <fmt/format.h>

#include "h5_error.h"

namespace tomorig::storage::h5 {

Datatype utf8_string_type() {
  Datatype type(check(H5Tcopy(H5T_C_S1), "cannot create", "a string type"));
  check(H5Tset_size(type.get(), H5T_VARIABLE), "cannot create", "a string type");
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "cannot create", "a string type");
  return type;
}

Datatype fixed_utf8_string_type(std::size_t bytes) {
  Datatype type(check(H5Tcopy(H5T_C_S1), "cannot create", "a string type"));
  check(H5Tset_size(type.get(), bytes == 0 ? 1 : bytes), "cannot create", "a string type");
  check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), "cannot create", "a string type");
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "cannot create", "a string type");
  return type;
}

namespace {

herr_t read_raw(hid_t object, StringSource source, hid_t mem_type, void* buffer) {
  return source == StringSource::attribute ? H5Aread(object, mem_type, buffer)
                                           : H5Dread(object, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer);
}

// Frees the strings HDF5 allocated for a variable-length read, even if copying them throws.
struct VlenBuffer {
  std::vector<char*> pointers;
  hid_t mem_type;
  hid_t space;
  ~VlenBuffer() { H5Dvlen_reclaim(mem_type, space, H5P_DEFAULT, pointers.data()); }
};

}  // namespace

std::vector<std::string> read_strings(hid_t object, StringSource source, std::string_view where) {
  const bool attr = source == StringSource::attribute;
  Datatype stored(check(attr ? H5Aget_type(object) : H5Dget_type(object), "cannot read the type of", where));
  if (H5Tget_class(stored.get()) != H5T_STRING) throw Failure(std::string(where) + " is not a string");
  Dataspace space(check(attr ? H5Aget_space(object) : H5Dget_space(object), "cannot read the shape of", where));
  const hssize_t points = check(H5Sget_simple_extent_npoints(space.get()), "cannot read the shape of", where);
  const auto count = static_cast<std::size_t>(points);

  const bool variable = H5Tis_variable_str(stored.get()) > 0;
  // Sized from the file before anything is allocated: a damaged extent or string size could
  // otherwise ask for terabytes, or wrap size * count around to a small buffer that HDF5 then
  // writes past.
  const std::size_t element_bytes = variable ? sizeof(char*) : H5Tget_size(stored.get());
  if (!variable && element_bytes == 0) throw Failure(std::string(where) + " has a string type of size 0");
  if (count > kMaxStringBytes / element_bytes)
    throw Failure(fmt::format("{} declares {} strings of {} bytes, more than the {} MiB strings of a tomorig file "
                              "can hold: the file is damaged",
                              where, count, variable ? std::string("variable length") : std::to_string(element_bytes),
                              kMaxStringBytes >> 20));

  Datatype mem(check(H5Tcopy(H5T_C_S1), "cannot read", where));
  check(H5Tset_cset(mem.get(), H5Tget_cset(stored.get())), "cannot read", where);
  std::vector<std::string> out;
  if (count == 0) return out;  // HDF5 rejects a read into a null buffer
  out.reserve(count);

  if (variable) {
    check(H5Tset_size(mem.get(), H5T_VARIABLE), "cannot read", where);
    VlenBuffer buffer{std::vector<char*>(count, nullptr), mem.get(), space.get()};
    check(read_raw(object, source, mem.get(), buffer.pointers.data()), "cannot read", where);
    for (const char* s : buffer.pointers) out.emplace_back(s != nullptr ? s : "");
    return out;
  }

  const std::size_t size = element_bytes;
  check(H5Tset_size(mem.get(), size), "cannot read", where);
  check(H5Tset_strpad(mem.get(), H5T_STR_NULLPAD), "cannot read", where);
  std::vector<char> raw(size * count, '\0');
  check(read_raw(object, source, mem.get(), raw.data()), "cannot read", where);
  for (std::size_t i = 0; i < count; ++i) {
    const char* s = raw.data() + i * size;
    out.emplace_back(s, strnlen(s, size));
  }
  return out;
}

}  // namespace tomorig::storage::h5
