// VolumeFileReader: reads and checks the volume layout of docs/file-formats.md.
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "h5_open.h"
#include "isolated_probe.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/volume_file.h"
#include "volume_layout.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = volume_layout;

struct VolumeFileReader::Impl {
  explicit Impl(const fs::path& p);

  [[noreturn]] void invalid(const std::string& what) const {
    throw bad_input(fmt::format("volume file '{}' is not a valid tomorig volume file: {}", path.string(), what));
  }
  [[noreturn]] void corrupt(const std::string& what) const {
    throw bad_input(fmt::format("volume file '{}' is corrupt or truncated: {}", path.string(), what));
  }
  StoredVolume read_volume(const std::string& name) const;
  std::vector<hsize_t> checked_dims(hid_t group, const char* dataset, const std::string& where) const;

  fs::path path;
  h5::File file;
  VolumeFileInfo info;
  std::vector<StoredVolume> volumes;
};

VolumeFileReader::Impl::Impl(const fs::path& p) : path(p) {
  file = h5::open_for_reading(path, "volume file");
  try {
    const hid_t root = file.get();
    if (!h5::has_attr(root, "format") || h5::read_string_attr(root, "format", "/") != layout::kFormatName)
      invalid(fmt::format("the root attribute 'format' is not '{}' (is it a session file? sessions are read by "
                          "'tomorig inspect')",
                          layout::kFormatName));
    const std::int64_t version = h5::read_int_attr(root, "format_version", "/");
    if (version < 1 || version > layout::kFormatVersion)
      invalid(fmt::format("format version {} is not supported (this tomorig reads up to {}{})", version,
                          layout::kFormatVersion, version > layout::kFormatVersion ? "; update tomorig" : ""));
    info.source_session = h5::read_string_attr(root, layout::kAttrSourceSession, "/");
    info.set_index = h5::read_uint64_attr(root, layout::kAttrSetIndex, "/");
    info.parameters_json = h5::read_string_dataset(root, layout::kParameters, "/parameters");
    h5::Group group = h5::open_group(root, layout::kVolumes, "/volumes");
    for (const std::string& name : h5::read_string_list_attr(group.get(), layout::kAttrOrder, "/volumes"))
      volumes.push_back(read_volume(name));
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
}

std::vector<hsize_t> VolumeFileReader::Impl::checked_dims(hid_t group, const char* dataset,
                                                           const std::string& where) const {
  h5::Dataset d = h5::open_dataset(group, dataset, where);
  return h5::dims_of(d.get(), where);
}

StoredVolume VolumeFileReader::Impl::read_volume(const std::string& name) const {
  const std::string where = layout::volume_path(name);
  h5::Group group = h5::open_group(file.get(), (std::string(layout::kVolumes) + "/" + name).c_str(), where);
  StoredVolume v;
  v.name = name;
  v.grid.nx = static_cast<int>(h5::read_int_attr(group.get(), layout::kAttrNx, where));
  v.grid.ny = static_cast<int>(h5::read_int_attr(group.get(), layout::kAttrNy, where));
  v.grid.nz = static_cast<int>(h5::read_int_attr(group.get(), layout::kAttrNz, where));
  const std::vector<double> origin = h5::read_doubles_attr(group.get(), layout::kAttrOrigin, 3, where);
  v.grid.origin = {origin[0], origin[1], origin[2]};
  v.grid.voxel_size = h5::read_double_attr(group.get(), layout::kAttrVoxelSize, where);
  if (v.grid.nx <= 0 || v.grid.ny <= 0 || v.grid.nz <= 0 || !(v.grid.voxel_size > 0) ||
      !std::isfinite(origin[0] + origin[1] + origin[2]))
    invalid(fmt::format("{} has grid {} x {} x {}, voxel size {}, origin ({}, {}, {})", where, v.grid.nx, v.grid.ny,
                        v.grid.nz, v.grid.voxel_size, origin[0], origin[1], origin[2]));
  v.attributes.algorithm = h5::read_string_attr(group.get(), layout::kAttrAlgorithm, where);
  v.attributes.exposure = h5::read_string_attr(group.get(), layout::kAttrExposure, where);
  v.attributes.report_json = h5::read_string_dataset(group.get(), layout::kReport, where + "/report");
  v.has_dense = h5::link_exists(group.get(), layout::kDense);
  v.has_sparse = h5::link_exists(group.get(), layout::kSparseIndex);
  if (!v.has_dense && !v.has_sparse) invalid(fmt::format("{} holds neither dense nor sparse data", where));
  if (v.has_dense) {
    const std::vector<hsize_t> expected{static_cast<hsize_t>(v.grid.nz), static_cast<hsize_t>(v.grid.ny),
                                        static_cast<hsize_t>(v.grid.nx)};
    const auto dims = checked_dims(group.get(), layout::kDense, where + "/dense");
    if (dims != expected)
      invalid(fmt::format("{}/dense has shape [{}] but the grid says [{}]", where, fmt::join(dims, ", "),
                          fmt::join(expected, ", ")));
  }
  if (v.has_sparse) {
    const auto index = checked_dims(group.get(), layout::kSparseIndex, where + "/sparse_index");
    const auto intensity = checked_dims(group.get(), layout::kSparseIntensity, where + "/sparse_intensity");
    if (index.size() != 1 || index != intensity)
      invalid(fmt::format("{}: sparse_index [{}] and sparse_intensity [{}] should be equal 1-D lists", where,
                          fmt::join(index, ", "), fmt::join(intensity, ", ")));
  }
  return v;
}

VolumeFileReader::VolumeFileReader(const fs::path& path) {
  h5::silence_errors();
  // The open pass runs in a child first: a library crash on a damaged file ends only the child.
  require_safe_to_read([&] { const Impl probe(path); }, "volume file", path);
  impl_ = std::make_unique<Impl>(path);
}
VolumeFileReader::~VolumeFileReader() = default;

const VolumeFileInfo& VolumeFileReader::info() const { return impl_->info; }
const std::vector<StoredVolume>& VolumeFileReader::volumes() const { return impl_->volumes; }

const StoredVolume& VolumeFileReader::volume(const std::string& name) const {
  for (const StoredVolume& v : impl_->volumes)
    if (v.name == name) return v;
  std::vector<std::string> names;
  for (const StoredVolume& v : impl_->volumes) names.push_back(v.name);
  throw bad_input(fmt::format("volume file '{}' has no volume '{}'; it holds: {}", impl_->path.string(), name,
                              names.empty() ? std::string("none") : fmt::format("{}", fmt::join(names, ", "))));
}

DenseVolume VolumeFileReader::read_dense(const std::string& name) const {
  h5::silence_errors();
  const StoredVolume& v = volume(name);
  if (!v.has_dense) return read_sparse(name).to_dense();
  DenseVolume dense(v.grid);
  const std::string where = layout::volume_path(name) + "/dense";
  try {
    h5::Dataset d = h5::open_dataset(impl_->file.get(), where.c_str(), where);
    h5::read_all(d.get(), H5T_NATIVE_FLOAT, dense.values.data(), where);
  } catch (const h5::Failure& failure) {
    impl_->corrupt(failure.what());
  }
  return dense;
}

SparseVolume VolumeFileReader::read_sparse(const std::string& name) const {
  h5::silence_errors();
  const StoredVolume& v = volume(name);
  SparseVolume sparse;
  sparse.grid = v.grid;
  if (!v.has_sparse) {
    const DenseVolume dense = read_dense(name);
    for (std::size_t n = 0; n < dense.values.size(); ++n) {
      if (dense.values[n] == 0.0f) continue;
      sparse.index.push_back(static_cast<std::uint32_t>(n));
      sparse.intensity.push_back(dense.values[n]);
    }
    return sparse;
  }
  const std::string where = layout::volume_path(name);
  try {
    h5::Dataset index = h5::open_dataset(impl_->file.get(), (where + "/sparse_index").c_str(), where);
    h5::Dataset intensity = h5::open_dataset(impl_->file.get(), (where + "/sparse_intensity").c_str(), where);
    const hsize_t n = h5::dims_of(index.get(), where)[0];
    sparse.index.resize(n);
    sparse.intensity.resize(n);
    if (n == 0) return sparse;  // HDF5 rejects a null buffer
    h5::read_all(index.get(), H5T_NATIVE_UINT32, sparse.index.data(), where + "/sparse_index");
    h5::read_all(intensity.get(), H5T_NATIVE_FLOAT, sparse.intensity.data(), where + "/sparse_intensity");
  } catch (const h5::Failure& failure) {
    impl_->corrupt(failure.what());
  }
  if (!sparse.index.empty() &&
      (sparse.index.back() >= v.grid.voxel_count() || !std::is_sorted(sparse.index.begin(), sparse.index.end())))
    impl_->invalid(fmt::format("{}/sparse_index is not ascending or points outside the grid", where));
  return sparse;
}

}  // namespace tomorig::storage
