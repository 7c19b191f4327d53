#pragma once
// Creating a results file (format version 2): the empty layout, and the room checks that run
// before HDF5 writes anything. Used by results_file_writer.cpp.
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "h5_handle.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::storage::results_detail {

// The interrogation grid shared by the sets of a file.
struct FieldShape {
  int nx = 0, ny = 0, nz = 0;
  Vec3d origin, spacing;
  bool operator==(const FieldShape&) const = default;
};
FieldShape shape_of(const VectorField& f);

// The fixed-length string type of /sets/completed_utc.
h5::Datatype utc_type();

// A new results file at `path`: root attributes, parameters and, with `shape`, the empty /sets
// rows and /statistics. Throws h5::Failure.
void create_new_file(const std::filesystem::path& path, const ResultsInfo& info, const std::string& created_utc,
                     const std::optional<FieldShape>& shape);

// Throws tomorig::Error (runtime) unless `bytes` more can be written into `file` (current size
// `size`): the free space of its file system and the process's file-size limit.
void require_room(const std::filesystem::path& file, std::uintmax_t size, std::uintmax_t bytes,
                  const std::string& what);

// Upper bounds of what a file grows by: its layout (statistics included), and one set.
inline constexpr std::uintmax_t kMetadataRoom = 32 * 1024;
std::uintmax_t layout_bytes(std::size_t nodes, const ResultsInfo& info);
std::uintmax_t set_bytes(const SetResult& r);

}  // namespace tomorig::storage::results_detail
