// ResultsReader: reads and checks the results layout of docs/file-formats.md. A set without
// its completion marker is ignored (the writer never leaves one, but another tool might).
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
#include "results_layout.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = results_layout;

struct ResultsReader::Impl {
  explicit Impl(const fs::path& p);
  [[noreturn]] void corrupt(const std::string& what) const {
    throw bad_input(fmt::format("results file '{}' is corrupt or truncated: {}", path.string(), what));
  }
  [[noreturn]] void invalid(const std::string& what) const {
    throw bad_input(fmt::format("results file '{}' is not a valid tomorig results file: {}", path.string(), what));
  }
  SetResult read_set(std::uint64_t index) const;

  fs::path path;
  h5::File file;
  ResultsInfo info;
  std::vector<std::uint64_t> indices;
};

ResultsReader::Impl::Impl(const fs::path& p) : path(p) {
  file = h5::open_for_reading(path, "results file");
  try {
    const hid_t root = file.get();
    if (!h5::has_attr(root, "format") || h5::read_string_attr(root, "format", "/") != layout::kFormatName)
      invalid(fmt::format("the root attribute 'format' is not '{}'", layout::kFormatName));
    const std::int64_t version = h5::read_int_attr(root, "format_version", "/");
    if (version < 1 || version > layout::kFormatVersion)
      invalid(fmt::format("format version {} is not supported (this tomorig reads up to {})", version,
                          layout::kFormatVersion));
    info.session_path = h5::read_string_attr(root, layout::kAttrSessionPath, "/");
    info.session_identity = h5::read_string_attr(root, layout::kAttrSessionIdentity, "/");
    info.voxel_size_mm = h5::read_double_attr(root, layout::kAttrVoxelSize, "/");
    info.software_version = h5::read_string_attr(root, "software_version", "/");
    info.parameters_json = h5::read_string_dataset(root, layout::kParameters, "/parameters");
    h5::Group sets = h5::open_group(root, layout::kSets, "/sets");
    H5G_info_t group_info;
    h5::check(H5Gget_info(sets.get(), &group_info), "cannot list", "/sets");
    for (hsize_t i = 0; i < group_info.nlinks; ++i) {
      char name[64] = {};
      if (H5Lget_name_by_idx(sets.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT) < 0)
        h5::fail("cannot list", "/sets");
      h5::Group g = h5::open_group(sets.get(), name, std::string("/sets/") + name);
      if (!h5::has_attr(g.get(), layout::kAttrComplete) ||
          h5::read_int_attr(g.get(), layout::kAttrComplete, name) != 1)
        continue;
      indices.push_back(h5::read_uint64_attr(g.get(), layout::kAttrSetIndex, std::string("/sets/") + name));
    }
    std::sort(indices.begin(), indices.end());
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
}

SetResult ResultsReader::Impl::read_set(std::uint64_t index) const {
  if (!std::binary_search(indices.begin(), indices.end(), index))
    throw bad_input(fmt::format("results file '{}' holds no finished set {} (it holds {} sets)", path.string(), index,
                                indices.size()));
  h5::silence_errors();
  const std::string name = layout::set_name(index);
  const std::string where = "/sets/" + name;
  SetResult r;
  try {
    h5::Group g = h5::open_group(file.get(), where.c_str(), where);
    r.set_index = index;
    r.dt_ns = h5::read_int_attr(g.get(), layout::kAttrDt, where);
    r.seconds = h5::read_double_attr(g.get(), layout::kAttrSeconds, where);
    r.completed_utc = h5::read_string_attr(g.get(), layout::kAttrCompleted, where);
    const auto nodes = h5::read_doubles_attr(g.get(), layout::kAttrNodes, 3, where);
    const auto origin = h5::read_doubles_attr(g.get(), layout::kAttrOrigin, 3, where);
    const auto spacing = h5::read_doubles_attr(g.get(), layout::kAttrSpacing, 3, where);
    if (!(nodes[0] >= 1 && nodes[1] >= 1 && nodes[2] >= 1 && nodes[0] * nodes[1] * nodes[2] < 1e10))
      invalid(fmt::format("{} has {} x {} x {} nodes", where, nodes[0], nodes[1], nodes[2]));
    VectorField f(static_cast<int>(nodes[0]), static_cast<int>(nodes[1]), static_cast<int>(nodes[2]));
    f.origin = {origin[0], origin[1], origin[2]};
    f.spacing = {spacing[0], spacing[1], spacing[2]};
    const std::vector<hsize_t> vec{static_cast<hsize_t>(f.nz), static_cast<hsize_t>(f.ny), static_cast<hsize_t>(f.nx), 3};
    const std::vector<hsize_t> scalar(vec.begin(), vec.begin() + 3);
    const auto read = [&](const char* dataset, const std::vector<hsize_t>& dims, hid_t type, void* out) {
      const std::string w = where + "/" + dataset;
      h5::Dataset d = h5::open_dataset(g.get(), dataset, w);
      const auto got = h5::dims_of(d.get(), w);
      if (got != dims)
        invalid(fmt::format("{} has shape [{}], expected [{}]", w, fmt::join(got, ", "), fmt::join(dims, ", ")));
      h5::read_all(d.get(), type, out, w);
    };
    read(layout::kDisplacement, vec, H5T_NATIVE_FLOAT, f.displacement.data());
    read(layout::kStatus, scalar, H5T_NATIVE_UINT8, f.status.data());
    read(layout::kPeak, scalar, H5T_NATIVE_FLOAT, f.peak.data());
    for (const VectorStatus s : f.status)
      if (static_cast<int>(s) > 2) invalid(fmt::format("{}/status holds {}, not 0, 1 or 2", where, static_cast<int>(s)));
    r.field = std::move(f);
    r.report_json = h5::read_string_dataset(g.get(), layout::kReport, where + "/report");
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
  return r;
}

ResultsReader::ResultsReader(const fs::path& path) : impl_(std::make_unique<Impl>(path)) {}
ResultsReader::~ResultsReader() = default;

const ResultsInfo& ResultsReader::info() const { return impl_->info; }
std::vector<std::uint64_t> ResultsReader::set_indices() const { return impl_->indices; }
SetResult ResultsReader::read_set(std::uint64_t set_index) const { return impl_->read_set(set_index); }

std::vector<SetResult> ResultsReader::read_all_sets() const {
  std::vector<SetResult> out;
  for (const std::uint64_t i : impl_->indices) out.push_back(impl_->read_set(i));
  return out;
}

bool ResultsReader::has_statistics() const { return !impl_->indices.empty(); }

// Recomputed from the stored sets: the same numbers as /statistics, which is there for
// ParaView and other readers.
EnsembleStatistics ResultsReader::statistics() const {
  if (impl_->indices.empty())
    throw bad_input(fmt::format("results file '{}' holds no finished set, so it has no statistics",
                                impl_->path.string()));
  return EnsembleStatistics::compute(read_all_sets(), impl_->info.voxel_size_mm);
}

}  // namespace tomorig::storage
