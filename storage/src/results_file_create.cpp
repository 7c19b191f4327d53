// Creating a results file (format version 2) and the room checks before writing (see
// results_file_create.h and results_file_writer.cpp).
#include "results_file_create.h"

#include <sys/resource.h>
#include <sys/statvfs.h>

#include <algorithm>
#include <array>
#include <limits>

#include <fmt/format.h>

#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "results_file_layout.h"
#include "results_file_rows.h"
#include "results_layout.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"

namespace tomorig::storage::results_detail {
namespace fs = std::filesystem;
namespace layout = results_layout;
namespace v2 = results_layout_v2;
namespace {

std::vector<hsize_t> field_dims(const FieldShape& s, hsize_t components) {
  std::vector<hsize_t> d{static_cast<hsize_t>(s.nz), static_cast<hsize_t>(s.ny), static_cast<hsize_t>(s.nx)};
  if (components > 1) d.push_back(components);
  return d;
}

void write_node_grid(hid_t object, const FieldShape& s, const std::string& where) {
  const std::array<hsize_t, 1> three{3};
  // Integers (issue 23: as float64 they broke numpy's reshape); readers accept either.
  const std::array<std::int32_t, 3> nodes{static_cast<std::int32_t>(s.nx), static_cast<std::int32_t>(s.ny),
                                          static_cast<std::int32_t>(s.nz)};
  const std::array<double, 3> o{s.origin.x, s.origin.y, s.origin.z};
  const std::array<double, 3> sp{s.spacing.x, s.spacing.y, s.spacing.z};
  h5::write_int32s_attr(object, layout::kAttrNodes, nodes, three, where);
  h5::write_doubles_attr(object, layout::kAttrOrigin, o, three, where);
  h5::write_doubles_attr(object, layout::kAttrSpacing, sp, three, where);
}

// A fixed-size statistics dataset, allocated at creation (SWMR cannot allocate later) and
// filled with NaN (or 0 for counts) until the first set.
void create_statistics_dataset(hid_t group, const char* name, hid_t type, const std::vector<hsize_t>& dims,
                               bool counts) {
  const std::string where = std::string("/statistics/") + name;
  h5::Dataspace space(h5::check(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                                "cannot create", where));
  h5::PropertyList dcpl(h5::check(H5Pcreate(H5P_DATASET_CREATE), "cannot create", where));
  h5::check(H5Pset_alloc_time(dcpl.get(), H5D_ALLOC_TIME_EARLY), "cannot configure", where);
  if (counts) {
    const std::uint64_t zero = 0;
    h5::check(H5Pset_fill_value(dcpl.get(), H5T_NATIVE_UINT64, &zero), "cannot configure", where);
  } else {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    h5::check(H5Pset_fill_value(dcpl.get(), H5T_NATIVE_DOUBLE, &nan), "cannot configure", where);
  }
  h5::Dataset d(h5::check(H5Dcreate2(group, name, type, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT),
                          "cannot create", where));
}

}  // namespace

FieldShape shape_of(const VectorField& f) { return {f.nx, f.ny, f.nz, f.origin, f.spacing}; }

h5::Datatype utc_type() {
  h5::Datatype t(h5::check(H5Tcopy(H5T_C_S1), "cannot create", "a string type"));
  h5::check(H5Tset_size(t.get(), v2::kUtcBytes), "cannot size", "a string type");
  h5::check(H5Tset_strpad(t.get(), H5T_STR_NULLTERM), "cannot configure", "a string type");
  return t;
}

// A new results file at `path`: root attributes, parameters and, once the interrogation grid is
// known, the empty /sets rows and /statistics. Written in the newest HDF5 format, which SWMR
// appending needs (HDF5 >= 1.10; h5py with HDF5 1.10, MATLAB R2021b+).
void create_new_file(const fs::path& path, const ResultsInfo& info, const std::string& created_utc,
                     const std::optional<FieldShape>& shape) {
  h5::PropertyList fapl(h5::check(H5Pcreate(H5P_FILE_ACCESS), "cannot create", "a file access list"));
  h5::check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "cannot configure",
            "a file access list");
  h5::File file(h5::check(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), "cannot create",
                          path.string()));
  const hid_t root = file.get();
  h5::write_string_attr(root, "format", layout::kFormatName, "/");
  h5::write_int_attr(root, "format_version", v2::kFormatVersion, H5T_STD_I32LE, "/");
  h5::write_string_attr(root, "software_version", software_version(), "/");
  h5::write_string_attr(root, "created_utc", created_utc, "/");
  h5::write_string_attr(root, layout::kAttrSessionPath, info.session_path, "/");
  h5::write_string_attr(root, layout::kAttrSessionIdentity, info.session_identity, "/");
  h5::write_double_attr(root, layout::kAttrVoxelSize, info.voxel_size_mm, "/");
  h5::write_string_dataset(root, layout::kParameters, info.parameters_json.empty() ? std::string("{}") : info.parameters_json,
                           "/parameters");
  if (shape) {
    h5::Group sets = h5::create_group(root, layout::kSets, "/sets");
    write_node_grid(sets.get(), *shape, "/sets");
    const hid_t g = sets.get();
    const auto v3 = field_dims(*shape, 3), v1 = field_dims(*shape, 1);
    // One set per chunk for the fields: appending writes whole chunks and touches no other set.
    // Per-set scalars share small chunks (2 KiB): a small file stays small.
    h5::RowDataset::create(g, v2::kComplete, H5T_STD_U8LE, {}, 256, "/sets/complete");
    h5::RowDataset::create(g, v2::kSetIndex, H5T_STD_U64LE, {}, 256, "/sets/set_index");
    h5::RowDataset::create(g, v2::kDt, H5T_STD_I64LE, {}, 256, "/sets/dt_ns");
    h5::RowDataset::create(g, v2::kSeconds, H5T_IEEE_F64LE, {}, 256, "/sets/seconds");
    h5::RowDataset::create(g, v2::kCompleted, utc_type().get(), {}, 64, "/sets/completed_utc");
    h5::RowDataset::create(g, v2::kReportSpan, H5T_STD_U64LE, {2}, 128, "/sets/report_span");
    h5::RowDataset::create(g, v2::kReportText, H5T_STD_U8LE, {}, 8192, "/sets/report_text");
    h5::RowDataset::create(g, layout::kDisplacement, H5T_IEEE_F32LE, v3, 1, "/sets/displacement_voxel");
    h5::RowDataset::create(g, layout::kVelocity, H5T_IEEE_F32LE, v3, 1, "/sets/velocity_m_s");
    h5::RowDataset::create(g, layout::kStatus, H5T_STD_U8LE, v1, 1, "/sets/status");
    h5::RowDataset::create(g, layout::kPeak, H5T_IEEE_F32LE, v1, 1, "/sets/peak");

    h5::Group stats = h5::create_group(root, layout::kStatistics, "/statistics");
    write_node_grid(stats.get(), *shape, "/statistics");
    auto v6 = v3;
    v6.back() = 6;
    create_statistics_dataset(stats.get(), v2::kStatisticsSets, H5T_STD_U64LE, {1}, true);
    create_statistics_dataset(stats.get(), layout::kValidCount, H5T_STD_U32LE, v1, true);
    create_statistics_dataset(stats.get(), layout::kMeanDisplacement, H5T_IEEE_F64LE, v3, false);
    create_statistics_dataset(stats.get(), layout::kMeanVelocity, H5T_IEEE_F64LE, v3, false);
    create_statistics_dataset(stats.get(), layout::kRmsVelocity, H5T_IEEE_F64LE, v3, false);
    create_statistics_dataset(stats.get(), layout::kReynoldsStress, H5T_IEEE_F64LE, v6, false);
  }
  if (file.close() < 0) h5::fail("cannot close", path.string());
}

// Room to write `bytes` more into `file` (whose current size is `size`): the free space of its
// file system, and the process's file-size limit. Failing this check before HDF5 writes anything
// matters: HDF5 1.10 cannot close a file whose metadata it failed to flush (the writer then
// abandons it; h5_error.cpp keeps HDF5's exit handler from crashing on it).
void require_room(const fs::path& file, std::uintmax_t size, std::uintmax_t bytes, const std::string& what) {
  std::uintmax_t room = std::numeric_limits<std::uintmax_t>::max();
  struct statvfs fs_info {};
  if (statvfs(file.parent_path().empty() ? "." : file.parent_path().c_str(), &fs_info) == 0)
    room = static_cast<std::uintmax_t>(fs_info.f_bavail) * fs_info.f_frsize;
  rlimit limit{};
  if (getrlimit(RLIMIT_FSIZE, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    room = std::min<std::uintmax_t>(room, limit.rlim_cur > size ? limit.rlim_cur - size : 0);
  if (room < bytes)
    throw runtime_error(fmt::format("{} needs about {} KiB more in '{}' but only {} KiB can be written there",
                                    what, (bytes + 1023) / 1024, file.string(), room / 1024));
}

// Upper bounds of what the file grows by: the data plus room for HDF5's metadata and the first
// chunks of the per-set scalars (which are allocated 2-8 KiB at a time).
std::uintmax_t layout_bytes(std::size_t nodes, const ResultsInfo& info) {
  return nodes * (4 + 3 * 8 * 3 + 6 * 8) + info.parameters_json.size() + kMetadataRoom;
}
std::uintmax_t set_bytes(const SetResult& r) {
  return r.field.count() * (12 + 12 + 1 + 4) + r.report_json.size() + kMetadataRoom;
}

}  // namespace tomorig::storage::results_detail
