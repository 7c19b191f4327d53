// ResultsReader: reads and checks the results layout of docs/file-formats.md, version 2 (sets
// as rows, appended in place) and version 1 (one group per set). A set counts only with its
// completion marker: version 2's /sets/complete byte, version 1's `complete` attribute. A file
// whose writer died opens too (in SWMR read mode, see h5_open.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
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
#include "results_file_layout.h"
#include "results_file_rows.h"
#include "results_layout.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/results_file.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = results_layout;
namespace v2 = results_layout_v2;

struct ResultsReader::Impl {
  explicit Impl(const fs::path& p);
  [[noreturn]] void corrupt(const std::string& what) const {
    throw bad_input(fmt::format("results file '{}' is corrupt or truncated: {}", path.string(), what));
  }
  [[noreturn]] void invalid(const std::string& what) const {
    throw bad_input(fmt::format("results file '{}' is not a valid tomorig results file: {}", path.string(), what));
  }
  void list_v1_sets();
  void list_v2_sets();
  SetResult read_set(std::uint64_t index) const;
  SetResult read_v1_set(std::uint64_t index) const;
  SetResult read_v2_set(std::uint64_t index, hsize_t row) const;
  VectorField node_grid(hid_t object, const std::string& where) const;

  fs::path path;
  h5::File file;
  int version = 0;
  ResultsInfo info;
  std::vector<std::uint64_t> indices;
  std::map<std::uint64_t, hsize_t> row_of;  // version 2
};

namespace {

// A write that failed for lack of space can leave the superblock's end-of-file address beyond
// the file's real end (space allocated for the set that could not be written). HDF5 then calls
// the file truncated, although every finished set lies before the real end. The writer extends
// the file back when it can; when it could not (the disk still full), this opens it anyway, with
// the check h5clear also skips. Reads past the end return zeros, which no completion byte is.
h5::File open_skipping_eof_check(const fs::path& path) {
  h5::PropertyList fapl(H5Pcreate(H5P_FILE_ACCESS));
  hbool_t skip = 1;
  if (!fapl.valid() || H5Pset(fapl.get(), "skip_eof_check", &skip) < 0) return h5::File();
  return h5::File(H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get()));
}

}  // namespace

ResultsReader::Impl::Impl(const fs::path& p) : path(p) {
  try {
    file = h5::open_for_reading(path, "results file");
  } catch (const Error& e) {
    if (std::string(e.what()).find("truncated file") == std::string::npos) throw;
    file = open_skipping_eof_check(path);
    if (!file.valid()) throw;
  }
  try {
    const hid_t root = file.get();
    if (!h5::has_attr(root, "format") || h5::read_string_attr(root, "format", "/") != layout::kFormatName)
      invalid(fmt::format("the root attribute 'format' is not '{}'", layout::kFormatName));
    const std::int64_t v = h5::read_int_attr(root, "format_version", "/");
    if (v != layout::kFormatVersion && v != v2::kFormatVersion)
      invalid(fmt::format("format version {} is not supported (this tomorig reads versions {} and {}); a newer tomorig "
                          "wrote it",
                          v, layout::kFormatVersion, v2::kFormatVersion));
    version = static_cast<int>(v);
    info.session_path = h5::read_string_attr(root, layout::kAttrSessionPath, "/");
    info.session_identity = h5::read_string_attr(root, layout::kAttrSessionIdentity, "/");
    info.voxel_size_mm = h5::read_double_attr(root, layout::kAttrVoxelSize, "/");
    info.software_version = h5::read_string_attr(root, "software_version", "/");
    info.parameters_json = h5::read_string_dataset(root, layout::kParameters, "/parameters");
    if (version == 1) list_v1_sets();
    else list_v2_sets();
    std::sort(indices.begin(), indices.end());
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
}

void ResultsReader::Impl::list_v1_sets() {
  h5::Group sets = h5::open_group(file.get(), layout::kSets, "/sets");
  H5G_info_t group_info;
  h5::check(H5Gget_info(sets.get(), &group_info), "cannot list", "/sets");
  for (hsize_t i = 0; i < group_info.nlinks; ++i) {
    char name[64] = {};
    if (H5Lget_name_by_idx(sets.get(), ".", H5_INDEX_NAME, H5_ITER_INC, i, name, sizeof name, H5P_DEFAULT) < 0)
      h5::fail("cannot list", "/sets");
    h5::Group g = h5::open_group(sets.get(), name, std::string("/sets/") + name);
    if (!h5::has_attr(g.get(), layout::kAttrComplete) || h5::read_int_attr(g.get(), layout::kAttrComplete, name) != 1)
      continue;
    indices.push_back(h5::read_uint64_attr(g.get(), layout::kAttrSetIndex, std::string("/sets/") + name));
  }
}

void ResultsReader::Impl::list_v2_sets() {
  // A file created before its first set has no /sets yet: it holds no set.
  if (!h5::link_exists(file.get(), layout::kSets)) return;
  h5::Group sets = h5::open_group(file.get(), layout::kSets, "/sets");
  const auto complete = h5::RowDataset::open(sets.get(), v2::kComplete, "/sets/complete");
  const auto set_index = h5::RowDataset::open(sets.get(), v2::kSetIndex, "/sets/set_index");
  const hsize_t rows = std::min(complete.rows(), set_index.rows());
  if (rows == 0) return;
  std::vector<std::uint8_t> done(rows);
  std::vector<std::uint64_t> index(rows);
  complete.read_rows(0, rows, H5T_NATIVE_UINT8, done.data());
  set_index.read_rows(0, rows, H5T_NATIVE_UINT64, index.data());
  for (hsize_t r = 0; r < rows; ++r)
    if (done[r] == 1) row_of[index[r]] = r;  // a set written twice (a retried write): the later row
  for (const auto& [i, row] : row_of) indices.push_back(i);
}

VectorField ResultsReader::Impl::node_grid(hid_t object, const std::string& where) const {
  const auto nodes = h5::read_doubles_attr(object, layout::kAttrNodes, 3, where);
  const auto origin = h5::read_doubles_attr(object, layout::kAttrOrigin, 3, where);
  const auto spacing = h5::read_doubles_attr(object, layout::kAttrSpacing, 3, where);
  if (!(nodes[0] >= 1 && nodes[1] >= 1 && nodes[2] >= 1 && nodes[0] * nodes[1] * nodes[2] < 1e10))
    invalid(fmt::format("{} has {} x {} x {} nodes", where, nodes[0], nodes[1], nodes[2]));
  VectorField f(static_cast<int>(nodes[0]), static_cast<int>(nodes[1]), static_cast<int>(nodes[2]));
  f.origin = {origin[0], origin[1], origin[2]};
  f.spacing = {spacing[0], spacing[1], spacing[2]};
  return f;
}

SetResult ResultsReader::Impl::read_set(std::uint64_t index) const {
  if (!std::binary_search(indices.begin(), indices.end(), index))
    throw bad_input(fmt::format("results file '{}' holds no finished set {} (it holds {} sets)", path.string(), index,
                                indices.size()));
  h5::silence_errors();
  SetResult r;
  try {
    r = version == 1 ? read_v1_set(index) : read_v2_set(index, row_of.at(index));
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
  for (const VectorStatus s : r.field.status)
    if (static_cast<int>(s) > 2)
      invalid(fmt::format("the status of set {} holds {}, not 0, 1 or 2", index, static_cast<int>(s)));
  return r;
}

SetResult ResultsReader::Impl::read_v1_set(std::uint64_t index) const {
  const std::string name = layout::set_name(index);
  const std::string where = "/sets/" + name;
  SetResult r;
  h5::Group g = h5::open_group(file.get(), where.c_str(), where);
  r.set_index = index;
  r.dt_ns = h5::read_int_attr(g.get(), layout::kAttrDt, where);
  r.seconds = h5::read_double_attr(g.get(), layout::kAttrSeconds, where);
  r.completed_utc = h5::read_string_attr(g.get(), layout::kAttrCompleted, where);
  VectorField f = node_grid(g.get(), where);
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
  r.field = std::move(f);
  r.report_json = h5::read_string_dataset(g.get(), layout::kReport, where + "/report");
  return r;
}

SetResult ResultsReader::Impl::read_v2_set(std::uint64_t index, hsize_t row) const {
  h5::Group sets = h5::open_group(file.get(), layout::kSets, "/sets");
  const hid_t g = sets.get();
  SetResult r;
  r.set_index = index;
  VectorField f = node_grid(g, "/sets");
  const auto rows = [&](const char* name, const std::vector<hsize_t>& record) {
    const std::string where = std::string("/sets/") + name;
    h5::RowDataset d = h5::RowDataset::open(g, name, where);
    if (d.rows() <= row) invalid(fmt::format("{} has {} rows, but set {} is in row {}", where, d.rows(), index, row));
    const std::vector<hsize_t> got = h5::dims_of(h5::open_dataset(g, name, where).get(), where);
    if (!std::equal(record.begin(), record.end(), got.begin() + 1, got.end()))
      invalid(fmt::format("{} has shape [{}], expected [rows, {}]", where, fmt::join(got, ", "), fmt::join(record, ", ")));
    return d;
  };
  const std::vector<hsize_t> vec{static_cast<hsize_t>(f.nz), static_cast<hsize_t>(f.ny), static_cast<hsize_t>(f.nx), 3};
  const std::vector<hsize_t> scalar(vec.begin(), vec.begin() + 3);
  rows(layout::kDisplacement, vec).read_rows(row, 1, H5T_NATIVE_FLOAT, f.displacement.data());
  rows(layout::kStatus, scalar).read_rows(row, 1, H5T_NATIVE_UINT8, f.status.data());
  rows(layout::kPeak, scalar).read_rows(row, 1, H5T_NATIVE_FLOAT, f.peak.data());
  rows(v2::kDt, {}).read_rows(row, 1, H5T_NATIVE_INT64, &r.dt_ns);
  rows(v2::kSeconds, {}).read_rows(row, 1, H5T_NATIVE_DOUBLE, &r.seconds);
  {
    h5::Datatype type(h5::check(H5Tcopy(H5T_C_S1), "cannot create", "a string type"));
    h5::check(H5Tset_size(type.get(), v2::kUtcBytes), "cannot size", "a string type");
    std::array<char, v2::kUtcBytes + 1> utc{};
    rows(v2::kCompleted, {}).read_rows(row, 1, type.get(), utc.data());
    r.completed_utc = std::string(utc.data());
  }
  std::array<std::uint64_t, 2> span{};
  rows(v2::kReportSpan, {2}).read_rows(row, 1, H5T_NATIVE_UINT64, span.data());
  const h5::RowDataset text = h5::RowDataset::open(g, v2::kReportText, "/sets/report_text");
  if (span[0] + span[1] > text.rows() || span[0] + span[1] < span[0])
    invalid(fmt::format("the report of set {} lies outside /sets/report_text", index));
  if (span[1] > 0) {
    r.report_json.resize(span[1]);
    text.read_rows(span[0], span[1], H5T_NATIVE_UINT8, r.report_json.data());  // bytes, unconverted
  }
  r.field = std::move(f);
  return r;
}

ResultsReader::ResultsReader(const fs::path& path) {
  h5::silence_errors();
  // The open pass runs in a child first: a library crash on a damaged file ends only the child.
  require_safe_to_read([&] { const Impl probe(path); }, "results file", path);
  impl_ = std::make_unique<Impl>(path);
}
ResultsReader::~ResultsReader() = default;

const ResultsInfo& ResultsReader::info() const { return impl_->info; }
int ResultsReader::format_version() const { return impl_->version; }
std::vector<std::uint64_t> ResultsReader::set_indices() const { return impl_->indices; }
SetResult ResultsReader::read_set(std::uint64_t set_index) const { return impl_->read_set(set_index); }

std::vector<SetResult> ResultsReader::read_all_sets() const {
  std::vector<SetResult> out;
  for (const std::uint64_t i : impl_->indices) out.push_back(impl_->read_set(i));
  return out;
}

bool ResultsReader::has_statistics() const { return !impl_->indices.empty(); }

// Recomputed from the stored sets, one at a time: the same numbers as /statistics, which is
// there for ParaView and other readers (and may lag the sets in a file whose writer died).
EnsembleStatistics ResultsReader::statistics() const {
  if (impl_->indices.empty())
    throw bad_input(fmt::format("results file '{}' holds no finished set, so it has no statistics",
                                impl_->path.string()));
  EnsembleAccumulator a(impl_->info.voxel_size_mm);
  for (const std::uint64_t i : impl_->indices) a.add(impl_->read_set(i));
  return a.result();
}

}  // namespace tomorig::storage
