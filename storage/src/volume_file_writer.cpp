// VolumeFileWriter: the volume layout of docs/file-formats.md in "<path>.partial", renamed into
// place together with its XDMF sidecar by finish().
#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>

#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "tomorig/storage/output_path.h"
#include "output_lock.h"
#include "partial_file.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/volume_file.h"
#include "utc_time.h"
#include "volume_layout.h"
#include "xdmf_sidecar.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = volume_layout;
namespace {

// Deflate level 1 after byte shuffling: reconstructed volumes are mostly zeros, which this
// shrinks ~20x at a few hundred MB/s, and deflate is built into every HDF5 (ParaView's too),
// unlike bitshuffle-LZ4.
constexpr unsigned kDeflateLevel = 1;

void check_volume_name(const std::string& name, const fs::path& file) {
  const bool ok = !name.empty() && name != "." && name != ".." &&
                  std::all_of(name.begin(), name.end(), [](unsigned char c) {
                    return std::isalnum(c) || c == '_' || c == '-' || c == '.';
                  });
  if (!ok)
    throw bad_input(fmt::format("volume file '{}': volume name '{}' is not allowed; use letters, digits, '_', '-' "
                                "and '.'",
                                file.string(), name));
}

void check_grid(const VoxelGrid& g, const std::string& name, const fs::path& file) {
  if (g.nx <= 0 || g.ny <= 0 || g.nz <= 0 || !(g.voxel_size > 0))
    throw bad_input(fmt::format("volume file '{}': volume '{}' has grid {} x {} x {} with voxel size {} mm; sizes "
                                "must be > 0",
                                file.string(), name, g.nx, g.ny, g.nz, g.voxel_size));
}

// One z-slice per chunk: ParaView and slice viewers read slices, and a 512 x 512 float slice
// (1 MiB) is a good deflate unit. Very large slices are split in y.
std::array<hsize_t, 3> dense_chunk(const VoxelGrid& g) {
  const hsize_t row_bytes = static_cast<hsize_t>(g.nx) * sizeof(float);
  const hsize_t rows = std::clamp<hsize_t>((4u << 20) / std::max<hsize_t>(row_bytes, 1), 1, g.ny);
  return {1, rows, static_cast<hsize_t>(g.nx)};
}

}  // namespace

struct VolumeFileWriter::Impl {
  Impl(const fs::path& path, const VolumeFileInfo& info, const VolumeFileOptions& options);

  h5::Group volume_group(const std::string& name, const VoxelGrid& grid, const VolumeAttributes& attributes);
  // Writes the dense dataset slice by slice from `slice_of(k, buffer)`.
  template <typename FillSlice>
  void write_dense(hid_t group, const std::string& where, const VoxelGrid& grid, FillSlice&& fill_slice);
  [[noreturn]] void fail(const std::string& action, const h5::Failure& failure);

  OutputLock lock;  // first declared, last released: after `partial` removed an unfinished file
  fs::path final_path;
  VolumeFileOptions options;
  PartialFile partial;
  h5::File file;
  h5::Group volumes;
  std::vector<std::string> order;
  std::vector<XdmfVolume> xdmf;
  std::vector<float> slice;  // reused between slices and volumes
  bool finished = false;
};

VolumeFileWriter::Impl::Impl(const fs::path& path, const VolumeFileInfo& info, const VolumeFileOptions& opts)
    : final_path(path), options(opts), partial(fs::path(path).concat(".partial")) {
  h5::silence_errors();
  check_output_path(final_path, options.overwrite, "volume");
  // A volume's partial file holds nothing until finish(), so one left by a killed writer is
  // replaced; the lock keeps a running writer's file from being replaced.
  lock = OutputLock::acquire(final_path, "volume");
  const fs::path sidecar = VolumeFileWriter::sidecar_path(final_path);
  std::error_code ec;
  if (fs::exists(sidecar, ec) && !options.overwrite)
    throw bad_input(fmt::format("XDMF file '{}' already exists; choose another name or allow overwriting "
                                "(--overwrite)",
                                sidecar.string()));
  const hid_t id = H5Fcreate(partial.path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (id < 0)
    throw bad_input(fmt::format("cannot create volume file '{}' (is folder '{}' writable?): {}",
                                partial.path().string(), partial.path().parent_path().string(),
                                h5::error_stack_text()));
  file = h5::File(id);
  partial.arm();
  try {
    const hid_t root = file.get();
    h5::write_string_attr(root, "format", layout::kFormatName, "/");
    h5::write_int_attr(root, "format_version", layout::kFormatVersion, H5T_STD_I32LE, "/");
    h5::write_string_attr(root, "software_version", software_version(), "/");
    h5::write_string_attr(root, "created_utc", utc_now_iso8601(), "/");
    h5::write_string_attr(root, layout::kAttrSourceSession, info.source_session, "/");
    h5::write_uint64_attr(root, layout::kAttrSetIndex, info.set_index, "/");
    h5::write_string_dataset(root, layout::kParameters,
                             info.parameters_json.empty() ? std::string("{}") : info.parameters_json, "/parameters");
    volumes = h5::create_group(root, layout::kVolumes, "/volumes");
  } catch (const h5::Failure& failure) {
    fail("creating the layout of", failure);
  }
}

void VolumeFileWriter::Impl::fail(const std::string& action, const h5::Failure& failure) {
  throw runtime_error(fmt::format("{} volume file '{}' failed (is the disk full?): {}", action,
                                  partial.path().string(), failure.what()));
}

h5::Group VolumeFileWriter::Impl::volume_group(const std::string& name, const VoxelGrid& grid,
                                               const VolumeAttributes& attributes) {
  if (finished) throw runtime_error(fmt::format("volume file '{}' is already finished", final_path.string()));
  check_volume_name(name, final_path);
  check_grid(grid, name, final_path);
  if (std::find(order.begin(), order.end(), name) != order.end())
    throw bad_input(fmt::format("volume file '{}': volume '{}' is added twice", final_path.string(), name));
  const std::string where = layout::volume_path(name);
  h5::Group group = h5::create_group(volumes.get(), name.c_str(), where);
  h5::write_int_attr(group.get(), layout::kAttrNx, grid.nx, H5T_STD_I32LE, where);
  h5::write_int_attr(group.get(), layout::kAttrNy, grid.ny, H5T_STD_I32LE, where);
  h5::write_int_attr(group.get(), layout::kAttrNz, grid.nz, H5T_STD_I32LE, where);
  const std::array<hsize_t, 1> three{3};
  const std::array<double, 3> origin{grid.origin.x, grid.origin.y, grid.origin.z};
  h5::write_doubles_attr(group.get(), layout::kAttrOrigin, origin, three, where);
  h5::write_double_attr(group.get(), layout::kAttrVoxelSize, grid.voxel_size, where);
  h5::write_string_attr(group.get(), layout::kAttrAlgorithm, attributes.algorithm, where);
  h5::write_string_attr(group.get(), layout::kAttrExposure, attributes.exposure, where);
  h5::write_string_dataset(group.get(), layout::kReport,
                           attributes.report_json.empty() ? std::string("{}") : attributes.report_json,
                           where + "/report");
  order.push_back(name);
  return group;
}

template <typename FillSlice>
void VolumeFileWriter::Impl::write_dense(hid_t group, const std::string& where, const VoxelGrid& grid,
                                         FillSlice&& fill_slice) {
  const std::string dataset_where = where + "/" + layout::kDense;
  const std::array<hsize_t, 3> dims{static_cast<hsize_t>(grid.nz), static_cast<hsize_t>(grid.ny),
                                    static_cast<hsize_t>(grid.nx)};
  const std::array<hsize_t, 3> chunk = dense_chunk(grid);
  h5::PropertyList dcpl(h5::check(H5Pcreate(H5P_DATASET_CREATE), "cannot create", dataset_where));
  h5::check(H5Pset_chunk(dcpl.get(), 3, chunk.data()), "cannot set the chunks of", dataset_where);
  h5::check(H5Pset_shuffle(dcpl.get()), "cannot set the shuffle filter of", dataset_where);
  h5::check(H5Pset_deflate(dcpl.get(), kDeflateLevel), "cannot set the deflate filter of", dataset_where);
  h5::Dataspace space(h5::check(H5Screate_simple(3, dims.data(), nullptr), "cannot create", dataset_where));
  h5::Dataset dataset(h5::check(H5Dcreate2(group, layout::kDense, H5T_IEEE_F32LE, space.get(), H5P_DEFAULT,
                                           dcpl.get(), H5P_DEFAULT),
                                "cannot create", dataset_where));
  const std::size_t slice_size = static_cast<std::size_t>(grid.nx) * static_cast<std::size_t>(grid.ny);
  slice.resize(slice_size);
  for (int k = 0; k < grid.nz; ++k) {
    fill_slice(k, slice);
    const std::array<hsize_t, 3> offset{static_cast<hsize_t>(k), 0, 0};
    const std::array<hsize_t, 3> count{1, dims[1], dims[2]};
    h5::write_block(dataset.get(), offset, count, H5T_NATIVE_FLOAT, slice.data(), dataset_where);
  }
  xdmf.push_back({where.substr(std::string("/volumes/").size()), grid,
                  final_path.filename().string() + ":" + dataset_where});
}

VolumeFileWriter::VolumeFileWriter(const fs::path& path, const VolumeFileInfo& info, const VolumeFileOptions& options)
    : impl_(std::make_unique<Impl>(path, info, options)) {}

VolumeFileWriter::~VolumeFileWriter() = default;

fs::path VolumeFileWriter::sidecar_path(const fs::path& volume_file) {
  return fs::path(volume_file).replace_extension(".xdmf");
}

void VolumeFileWriter::add(const std::string& name, const SparseVolume& volume, const VolumeAttributes& attributes) {
  h5::silence_errors();
  Impl& m = *impl_;
  const VoxelGrid& g = volume.grid;
  if (volume.index.size() != volume.intensity.size())
    throw bad_input(fmt::format("volume '{}' has {} indices but {} intensities", name, volume.index.size(),
                                volume.intensity.size()));
  if (!volume.index.empty() && (volume.index.back() >= g.voxel_count() ||
                                !std::is_sorted(volume.index.begin(), volume.index.end())))
    throw bad_input(fmt::format("volume '{}': sparse indices must be ascending and inside the {} x {} x {} grid",
                                name, g.nx, g.ny, g.nz));
  try {
    h5::Group group = m.volume_group(name, g, attributes);
    const std::string where = layout::volume_path(name);
    const std::array<hsize_t, 1> n{volume.size()};
    h5::write_dataset(group.get(), layout::kSparseIndex, H5T_STD_U32LE, n, H5T_NATIVE_UINT32, volume.index.data(),
                      where + "/" + layout::kSparseIndex);
    h5::write_dataset(group.get(), layout::kSparseIntensity, H5T_IEEE_F32LE, n, H5T_NATIVE_FLOAT,
                      volume.intensity.data(), where + "/" + layout::kSparseIntensity);
    if (!m.options.dense_export) return;
    // Indices are ascending, so each z-slice is one contiguous run of the list.
    const std::size_t slice_size = static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny);
    std::size_t next = 0;
    m.write_dense(group.get(), where, g, [&](int k, std::vector<float>& slice) {
      std::fill(slice.begin(), slice.end(), 0.0f);
      const std::size_t end = slice_size * static_cast<std::size_t>(k + 1);
      const std::size_t base = slice_size * static_cast<std::size_t>(k);
      for (; next < volume.size() && volume.index[next] < end; ++next)
        slice[volume.index[next] - base] = volume.intensity[next];
    });
  } catch (const h5::Failure& failure) {
    m.fail(fmt::format("writing volume '{}' to", name), failure);
  }
}

void VolumeFileWriter::add(const std::string& name, const DenseVolume& volume, const VolumeAttributes& attributes) {
  h5::silence_errors();
  Impl& m = *impl_;
  const VoxelGrid& g = volume.grid;
  if (volume.values.size() != g.voxel_count())
    throw bad_input(fmt::format("volume '{}' holds {} values but its {} x {} x {} grid has {} voxels", name,
                                volume.values.size(), g.nx, g.ny, g.nz, g.voxel_count()));
  try {
    h5::Group group = m.volume_group(name, g, attributes);
    const std::size_t slice_size = static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny);
    m.write_dense(group.get(), layout::volume_path(name), g, [&](int k, std::vector<float>& slice) {
      const auto first = volume.values.begin() + static_cast<std::ptrdiff_t>(slice_size * static_cast<std::size_t>(k));
      std::copy(first, first + static_cast<std::ptrdiff_t>(slice_size), slice.begin());
    });
  } catch (const h5::Failure& failure) {
    m.fail(fmt::format("writing volume '{}' to", name), failure);
  }
}

void VolumeFileWriter::finish() {
  h5::silence_errors();
  Impl& m = *impl_;
  if (m.finished) throw runtime_error(fmt::format("volume file '{}' is already finished", m.final_path.string()));
  try {
    h5::write_string_list_attr(m.volumes.get(), layout::kAttrOrder, m.order, "/volumes");
  } catch (const h5::Failure& failure) {
    m.fail("finishing", failure);
  }
  m.volumes.reset();
  if (m.file.close() < 0)
    throw runtime_error(fmt::format("closing volume file '{}' failed, so it may be incomplete (is the disk full?): {}",
                                    m.partial.path().string(), h5::error_stack_text()));

  // The sidecar goes into place first: a volume file with dense data under its final name always
  // has one. Without dense data (sparse only) there is nothing for ParaView to show, so none.
  const fs::path sidecar = sidecar_path(m.final_path);
  std::error_code ec;
  if (m.xdmf.empty()) {
    fs::remove(sidecar, ec);  // an old sidecar (overwrite) would point at data that is gone
  } else {
    PartialFile sidecar_partial(fs::path(sidecar).concat(".partial"));
    {
      std::ofstream out(sidecar_partial.path(), std::ios::binary | std::ios::trunc);
      sidecar_partial.arm();
      out << xdmf_for_volumes(m.xdmf);
      out.close();
      if (!out)
        throw runtime_error(
            fmt::format("cannot write XDMF file '{}' (is the disk full?)", sidecar_partial.path().string()));
    }
    fs::rename(sidecar_partial.path(), sidecar, ec);
    if (ec) throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", sidecar_partial.path().string(),
                                            sidecar.string(), ec.message()));
    sidecar_partial.release();
  }
  fs::rename(m.partial.path(), m.final_path, ec);
  if (ec) throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", m.partial.path().string(),
                                          m.final_path.string(), ec.message()));
  m.partial.release();
  m.finished = true;
  m.lock = OutputLock();  // done: the name is free for another writer
}

}  // namespace tomorig::storage
