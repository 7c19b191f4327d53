#pragma once
// Dataset and group helpers. `where` names the object in error messages; failures throw
// h5::Failure.
#include <hdf5.h>

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "h5_handle.h"

namespace tomorig::storage::h5 {

bool link_exists(hid_t location, const char* name);
Group create_group(hid_t location, const char* name, std::string_view where);
// Throws Failure("<where> is missing") if there is no such group.
Group open_group(hid_t location, const char* name, std::string_view where);
Dataset open_dataset(hid_t location, const char* name, std::string_view where);
// Same, with a chunk cache of `cache_bytes` for this dataset.
Dataset open_dataset(hid_t location, const char* name, std::size_t cache_bytes, std::string_view where);

// Chunk cache for a dataset of whole-frame chunks, measured with 1024 x 1024 uint16 frames
// on the 2-core build machine (figures in docs/file-formats.md, "Performance"):
//  - unfiltered: 0, no cache. HDF5 then writes and reads a whole chunk straight from and to
//    the caller's buffer; a cache only adds a copy (2-3x slower).
//  - filtered: exactly one chunk. Without a cache HDF5 runs the filter through freshly
//    allocated, zero-filled buffers per chunk (160 MB/s with bitshuffle-LZ4); with room for
//    one chunk it reuses them (450-700 MB/s); room for more chunks is slower again.
std::size_t frame_chunk_cache_bytes(bool filtered, std::size_t chunk_bytes);

std::vector<hsize_t> dims_of(hid_t dataset, std::string_view where);

// Reads or writes the block [offset, offset + count) of a dataset from or to a contiguous
// memory buffer of `mem_type`.
void read_block(hid_t dataset, std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type,
                void* out, std::string_view where);
void write_block(hid_t dataset, std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type,
                 const void* data, std::string_view where);
// Reads a whole dataset, converted to `mem_type`, into `out` (which must be large enough).
void read_all(hid_t dataset, hid_t mem_type, void* out, std::string_view where);

// A fixed-size dataset of `file_type` with shape `dims`, written in one go (contiguous layout).
void write_dataset(hid_t location, const char* name, hid_t file_type, std::span<const hsize_t> dims,
                   hid_t mem_type, const void* data, std::string_view where);

// A scalar variable-length UTF-8 string dataset (e.g. /parameters of results files).
void write_string_dataset(hid_t location, const char* name, std::string_view text, std::string_view where);
// A scalar fixed-length UTF-8 string dataset as long as `text` (/config of session files).
void write_fixed_string_dataset(hid_t location, const char* name, std::string_view text, std::string_view where);
std::string read_string_dataset(hid_t location, const char* name, std::string_view where);

// A chunked dataset whose first dimension starts at 0 and grows without limit, one set at a
// time. It stays open for the life of the writer: reopening per frame costs more than the
// write itself for small frames.
class GrowingDataset {
 public:
  struct Options {
    hid_t file_type = H5T_STD_U8LE;
    std::vector<hsize_t> record_shape;  // dimensions after the first
    std::vector<hsize_t> chunk;         // full chunk shape, first dimension included
    hid_t dcpl = H5P_DEFAULT;           // filters; the chunk shape is added to a copy
    // Chunk cache size in bytes; kDefaultCache keeps HDF5's default (1 MiB). See
    // frame_chunk_cache_bytes() for why frames set it.
    std::size_t chunk_cache_bytes = kDefaultCache;
  };
  static constexpr std::size_t kDefaultCache = static_cast<std::size_t>(-1);

  GrowingDataset() = default;
  GrowingDataset(hid_t location, const char* name, std::string where, const Options& options);

  // Extends the first dimension to `records`.
  void grow_to(hsize_t records);
  void write(std::span<const hsize_t> offset, std::span<const hsize_t> count, hid_t mem_type, const void* data);
  // Writes one full record (all dimensions after the first) at `record`.
  void write_record(hsize_t record, hid_t mem_type, const void* data);
  herr_t close() { return dataset_.close(); }
  const std::string& where() const { return where_; }

 private:
  Dataset dataset_;
  std::string where_;
  std::vector<hsize_t> dims_;    // current extent
  std::vector<hsize_t> offset_;  // scratch for write_record
  std::vector<hsize_t> count_;   // one record
};

}  // namespace tomorig::storage::h5
