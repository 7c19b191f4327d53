#include "h5_datasets.h"

#include "h5_error.h"
#include "h5_strings.h"

namespace tomorig::storage::h5 {

bool link_exists(hid_t location, const char* name) { return H5Lexists(location, name, H5P_DEFAULT) > 0; }

Group create_group(hid_t location, const char* name, std::string_view where) {
  return Group(check(H5Gcreate2(location, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "cannot create", where));
}

Group open_group(hid_t location, const char* name, std::string_view where) {
  if (!link_exists(location, name)) throw Failure(std::string(where) + " is missing");
  return Group(check(H5Gopen2(location, name, H5P_DEFAULT), "cannot open", where));
}

Dataset open_dataset(hid_t location, const char* name, std::string_view where) {
  if (!link_exists(location, name)) throw Failure(std::string(where) + " is missing");
  return Dataset(check(H5Dopen2(location, name, H5P_DEFAULT), "cannot open", where));
}

namespace {
PropertyList access_list(std::size_t cache_bytes, std::string_view where) {
  PropertyList dapl(check(H5Pcreate(H5P_DATASET_ACCESS), "cannot create an access list for", where));
  // w0 = 1: evict fully written or read chunks first; they will not be touched again.
  check(H5Pset_chunk_cache(dapl.get(), H5D_CHUNK_CACHE_NSLOTS_DEFAULT, cache_bytes, 1.0),
        "cannot set the chunk cache of", where);
  return dapl;
}
}  // namespace

Dataset open_dataset(hid_t location, const char* name, std::size_t cache_bytes, std::string_view where) {
  if (!link_exists(location, name)) throw Failure(std::string(where) + " is missing");
  PropertyList dapl = access_list(cache_bytes, where);
  return Dataset(check(H5Dopen2(location, name, dapl.get()), "cannot open", where));
}

std::size_t frame_chunk_cache_bytes(bool filtered, std::size_t chunk_bytes) { return filtered ? chunk_bytes : 0; }

std::vector<hsize_t> dims_of(hid_t dataset, std::string_view where) {
  Dataspace space(check(H5Dget_space(dataset), "cannot read the shape of", where));
  const int rank = check(H5Sget_simple_extent_ndims(space.get()), "cannot read the shape of", where);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  check(H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr), "cannot read the shape of", where);
  return dims;
}

namespace {

hsize_t product(std::span<const hsize_t> dims) {
  hsize_t n = 1;
  for (hsize_t d : dims) n *= d;
  return n;
}

// File and memory dataspaces for a block of a dataset.
struct BlockSpaces {
  Dataspace file;
  Dataspace memory;
};

BlockSpaces block_spaces(hid_t dataset, std::span<const hsize_t> offset, std::span<const hsize_t> count,
                         const char* action, std::string_view where) {
  BlockSpaces s;
  s.file = Dataspace(check(H5Dget_space(dataset), action, where));
  check(H5Sselect_hyperslab(s.file.get(), H5S_SELECT_SET, offset.data(), nullptr, count.data(), nullptr), action,
        where);
  // The memory space has the block's own shape, not a flat 1-D one: HDF5 maps a selection to
  // chunks with a fast path only when memory and file selections have the same shape, and
  // otherwise walks the selection element by element (eight times slower for whole frames).
  s.memory = Dataspace(check(H5Screate_simple(static_cast<int>(count.size()), count.data(), nullptr), action, where));
  return s;
}

}  // namespace

void read_block(hid_t dataset, std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type,
                void* out, std::string_view where) {
  BlockSpaces s = block_spaces(dataset, offset, count, "cannot read", where);
  check(H5Dread(dataset, mem_type, s.memory.get(), s.file.get(), H5P_DEFAULT, out), "cannot read", where);
}

void write_block(hid_t dataset, std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type,
                 const void* data, std::string_view where) {
  BlockSpaces s = block_spaces(dataset, offset, count, "cannot write", where);
  check(H5Dwrite(dataset, mem_type, s.memory.get(), s.file.get(), H5P_DEFAULT, data), "cannot write", where);
}

void read_all(hid_t dataset, hid_t mem_type, void* out, std::string_view where) {
  check(H5Dread(dataset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out), "cannot read", where);
}

void write_dataset(hid_t location, const char* name, hid_t file_type, std::span<const hsize_t> dims,
                   hid_t mem_type, const void* data, std::string_view where) {
  Dataspace space(check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), "cannot create", where));
  Dataset dataset(check(H5Dcreate2(location, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        "cannot create", where));
  if (product(dims) == 0) return;  // nothing to write; HDF5 rejects a null buffer
  check(H5Dwrite(dataset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "cannot write", where);
}

void write_string_dataset(hid_t location, const char* name, std::string_view text, std::string_view where) {
  Datatype type = utf8_string_type();
  Dataspace space(check(H5Screate(H5S_SCALAR), "cannot create", where));
  Dataset dataset(check(H5Dcreate2(location, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        "cannot create", where));
  const std::string copy(text);
  const char* pointer = copy.c_str();
  check(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, &pointer), "cannot write", where);
}

void write_fixed_string_dataset(hid_t location, const char* name, std::string_view text, std::string_view where) {
  Datatype type = fixed_utf8_string_type(text.size());
  Dataspace space(check(H5Screate(H5S_SCALAR), "cannot create", where));
  Dataset dataset(check(H5Dcreate2(location, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                        "cannot create", where));
  std::string padded(text);
  padded.resize(H5Tget_size(type.get()), '\0');
  check(H5Dwrite(dataset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, padded.data()), "cannot write", where);
}

std::string read_string_dataset(hid_t location, const char* name, std::string_view where) {
  Dataset dataset = open_dataset(location, name, where);
  auto values = read_strings(dataset.get(), StringSource::dataset, where);
  if (values.size() != 1)
    throw Failure(std::string(where) + " should hold one string but holds " + std::to_string(values.size()));
  return std::move(values.front());
}

GrowingDataset::GrowingDataset(hid_t location, const char* name, std::string where, const Options& options)
    : where_(std::move(where)) {
  const int rank = static_cast<int>(options.record_shape.size() + 1);
  dims_.assign(1, 0);
  dims_.insert(dims_.end(), options.record_shape.begin(), options.record_shape.end());
  std::vector<hsize_t> max_dims = dims_;
  max_dims[0] = H5S_UNLIMITED;
  offset_.assign(dims_.size(), 0);
  count_ = dims_;
  count_[0] = 1;

  Dataspace space(check(H5Screate_simple(rank, dims_.data(), max_dims.data()), "cannot create", where_));
  PropertyList dcpl(check(options.dcpl == H5P_DEFAULT ? H5Pcreate(H5P_DATASET_CREATE) : H5Pcopy(options.dcpl),
                          "cannot create", where_));
  check(H5Pset_chunk(dcpl.get(), rank, options.chunk.data()), "cannot set the chunk shape of", where_);
  PropertyList dapl = options.chunk_cache_bytes == kDefaultCache
                          ? PropertyList(check(H5Pcreate(H5P_DATASET_ACCESS), "cannot create", where_))
                          : access_list(options.chunk_cache_bytes, where_);
  dataset_ = Dataset(check(H5Dcreate2(location, name, options.file_type, space.get(), H5P_DEFAULT, dcpl.get(),
                                      dapl.get()),
                           "cannot create", where_));
}

void GrowingDataset::grow_to(hsize_t records) {
  dims_[0] = records;
  check(H5Dset_extent(dataset_.get(), dims_.data()), "cannot extend", where_);
}

void GrowingDataset::write(std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type,
                           const void* data) {
  write_block(dataset_.get(), offset, count, mem_type, data, where_);
}

void GrowingDataset::write_record(hsize_t record, hid_t mem_type, const void* data) {
  offset_[0] = record;
  write_block(dataset_.get(), offset_, count_, mem_type, data, where_);
}

}  // namespace tomorig::storage::h5
