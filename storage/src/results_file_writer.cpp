// ResultsWriter: every add() rewrites the whole results file into "<path>.partial" and renames
// it into place, so the file under the final name is always complete (see results_file.h).
// Results are small (a 64 x 64 x 20 field is ~0.3 MB per set), so the rewrite costs far less
// than processing a set.
#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <limits>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "output_path.h"
#include "partial_file.h"
#include "results_layout.h"
#include "results_xdmf.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/results_file.h"
#include "utc_time.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = results_layout;
namespace {

static_assert(sizeof(Vec3f) == 3 * sizeof(float) && std::is_standard_layout_v<Vec3f>);
static_assert(sizeof(Vec3d) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3d>);
static_assert(sizeof(VectorStatus) == 1);

std::array<hsize_t, 4> field_dims(int nx, int ny, int nz, hsize_t components) {
  return {static_cast<hsize_t>(nz), static_cast<hsize_t>(ny), static_cast<hsize_t>(nx), components};
}

void write_node_grid(hid_t object, int nx, int ny, int nz, const Vec3d& origin, const Vec3d& spacing,
                     const std::string& where) {
  const std::array<hsize_t, 1> three{3};
  const std::array<double, 3> nodes{static_cast<double>(nx), static_cast<double>(ny), static_cast<double>(nz)};
  const std::array<double, 3> o{origin.x, origin.y, origin.z};
  const std::array<double, 3> s{spacing.x, spacing.y, spacing.z};
  h5::write_doubles_attr(object, layout::kAttrNodes, nodes, three, where);
  h5::write_doubles_attr(object, layout::kAttrOrigin, o, three, where);
  h5::write_doubles_attr(object, layout::kAttrSpacing, s, three, where);
}

void write_set(hid_t sets, const SetResult& r, double voxel_size_mm) {
  const std::string name = layout::set_name(r.set_index);
  const std::string where = std::string("/sets/") + name;
  h5::Group g = h5::create_group(sets, name.c_str(), where);
  const VectorField& f = r.field;
  write_node_grid(g.get(), f.nx, f.ny, f.nz, f.origin, f.spacing, where);
  h5::write_uint64_attr(g.get(), layout::kAttrSetIndex, r.set_index, where);
  h5::write_int_attr(g.get(), layout::kAttrDt, r.dt_ns, H5T_STD_I64LE, where);
  h5::write_double_attr(g.get(), layout::kAttrSeconds, r.seconds, where);
  h5::write_string_attr(g.get(), layout::kAttrCompleted, r.completed_utc, where);
  const auto vec = field_dims(f.nx, f.ny, f.nz, 3);
  const std::span<const hsize_t> scalar(vec.data(), 3);
  h5::write_dataset(g.get(), layout::kDisplacement, H5T_IEEE_F32LE, vec, H5T_NATIVE_FLOAT, f.displacement.data(),
                    where + "/" + layout::kDisplacement);
  std::vector<float> velocity(3 * f.count());
  for (std::size_t i = 0; i < f.count(); ++i) {
    const Vec3f& d = f.displacement[i];
    velocity[3 * i] = static_cast<float>(velocity_m_per_s(d.x, voxel_size_mm, r.dt_ns));
    velocity[3 * i + 1] = static_cast<float>(velocity_m_per_s(d.y, voxel_size_mm, r.dt_ns));
    velocity[3 * i + 2] = static_cast<float>(velocity_m_per_s(d.z, voxel_size_mm, r.dt_ns));
  }
  h5::write_dataset(g.get(), layout::kVelocity, H5T_IEEE_F32LE, vec, H5T_NATIVE_FLOAT, velocity.data(),
                    where + "/" + layout::kVelocity);
  h5::write_dataset(g.get(), layout::kStatus, H5T_STD_U8LE, scalar, H5T_NATIVE_UINT8, f.status.data(),
                    where + "/" + layout::kStatus);
  h5::write_dataset(g.get(), layout::kPeak, H5T_IEEE_F32LE, scalar, H5T_NATIVE_FLOAT, f.peak.data(),
                    where + "/" + layout::kPeak);
  h5::write_string_dataset(g.get(), layout::kReport, r.report_json.empty() ? std::string("{}") : r.report_json,
                           where + "/report");
  // Written last: a reader trusts a set only with this marker.
  h5::write_int_attr(g.get(), layout::kAttrComplete, 1, H5T_STD_U8LE, where);
}

void write_statistics(hid_t root, const EnsembleStatistics& s) {
  const std::string where = "/statistics";
  h5::Group g = h5::create_group(root, layout::kStatistics, where);
  write_node_grid(g.get(), s.nx, s.ny, s.nz, s.origin, s.spacing, where);
  h5::write_uint64_attr(g.get(), layout::kAttrSetCount, s.sets, where);
  const auto v3 = field_dims(s.nx, s.ny, s.nz, 3);
  const auto v6 = field_dims(s.nx, s.ny, s.nz, 6);
  h5::write_dataset(g.get(), layout::kValidCount, H5T_STD_U32LE, std::span<const hsize_t>(v3.data(), 3),
                    H5T_NATIVE_UINT32, s.valid_count.data(), where + "/" + layout::kValidCount);
  h5::write_dataset(g.get(), layout::kMeanDisplacement, H5T_IEEE_F64LE, v3, H5T_NATIVE_DOUBLE,
                    s.mean_displacement_voxel.data(), where + "/" + layout::kMeanDisplacement);
  h5::write_dataset(g.get(), layout::kMeanVelocity, H5T_IEEE_F64LE, v3, H5T_NATIVE_DOUBLE, s.mean_velocity.data(),
                    where + "/" + layout::kMeanVelocity);
  h5::write_dataset(g.get(), layout::kRmsVelocity, H5T_IEEE_F64LE, v3, H5T_NATIVE_DOUBLE, s.rms_velocity.data(),
                    where + "/" + layout::kRmsVelocity);
  h5::write_dataset(g.get(), layout::kReynoldsStress, H5T_IEEE_F64LE, v6, H5T_NATIVE_DOUBLE,
                    s.reynolds_stress.data(), where + "/" + layout::kReynoldsStress);
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  PartialFile partial(fs::path(path).concat(".partial"));
  {
    std::ofstream out(partial.path(), std::ios::binary | std::ios::trunc);
    partial.arm();
    out << text;
    out.close();
    if (!out) throw runtime_error(fmt::format("cannot write XDMF file '{}' (is the disk full?)", partial.path().string()));
  }
  std::error_code ec;
  fs::rename(partial.path(), path, ec);
  if (ec)
    throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", partial.path().string(), path.string(), ec.message()));
  partial.release();
}

}  // namespace

struct ResultsWriter::Impl {
  fs::path path;
  ResultsInfo info;
  std::string created_utc;
  std::vector<SetResult> sets;
  std::uint64_t resumed = 0;

  void write_file() const;
};

void ResultsWriter::Impl::write_file() const {
  h5::silence_errors();
  PartialFile partial(fs::path(path).concat(".partial"));
  const auto failed = [&](const std::string& why) {
    return runtime_error(fmt::format("writing results file '{}' failed (is the disk full?): {}; '{}' is unchanged and "
                                     "still holds the sets finished before",
                                     partial.path().string(), why, path.string()));
  };
  // The file is built in memory (HDF5 core driver, no backing store) and written out as one
  // image: a failing disk then fails a plain write, and HDF5 never holds a half-written file
  // open (a failed H5Fclose on a full disk leaves state behind that HDF5 trips over at exit).
  std::vector<char> image;
  {
    h5::PropertyList fapl(H5Pcreate(H5P_FILE_ACCESS));
    if (!fapl.valid() || H5Pset_fapl_core(fapl.get(), 1 << 20, 0) < 0)
      throw failed("cannot set up an in-memory HDF5 file: " + h5::error_stack_text());
    const hid_t id = H5Fcreate(partial.path().c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
    if (id < 0) throw failed("cannot create the in-memory HDF5 file: " + h5::error_stack_text());
    h5::File file(id);
    try {
      const hid_t root = file.get();
      h5::write_string_attr(root, "format", layout::kFormatName, "/");
      h5::write_int_attr(root, "format_version", layout::kFormatVersion, H5T_STD_I32LE, "/");
      h5::write_string_attr(root, "software_version", software_version(), "/");
      h5::write_string_attr(root, "created_utc", created_utc, "/");
      h5::write_string_attr(root, "modified_utc", utc_now_iso8601(), "/");
      h5::write_string_attr(root, layout::kAttrSessionPath, info.session_path, "/");
      h5::write_string_attr(root, layout::kAttrSessionIdentity, info.session_identity, "/");
      h5::write_double_attr(root, layout::kAttrVoxelSize, info.voxel_size_mm, "/");
      h5::write_string_dataset(root, layout::kParameters,
                               info.parameters_json.empty() ? std::string("{}") : info.parameters_json, "/parameters");
      h5::Group group = h5::create_group(root, layout::kSets, "/sets");
      for (const SetResult& r : sets) write_set(group.get(), r, info.voxel_size_mm);
      group.reset();
      if (!sets.empty()) write_statistics(root, EnsembleStatistics::compute(sets, info.voxel_size_mm));
      h5::check(H5Fflush(root, H5F_SCOPE_GLOBAL), "cannot flush", "the results file");
      const ssize_t size = H5Fget_file_image(root, nullptr, 0);
      if (size <= 0) h5::fail("cannot get the image of", "the results file");
      image.resize(static_cast<std::size_t>(size));
      if (H5Fget_file_image(root, image.data(), image.size()) != size) h5::fail("cannot get the image of", "the results file");
    } catch (const h5::Failure& failure) {
      throw failed(failure.what());
    }
  }
  {
    std::ofstream out(partial.path(), std::ios::binary | std::ios::trunc);
    if (!out)
      throw runtime_error(fmt::format("cannot create results file '{}' (is folder '{}' writable?)",
                                      partial.path().string(), partial.path().parent_path().string()));
    partial.arm();
    out.write(image.data(), static_cast<std::streamsize>(image.size()));
    out.close();
    if (!out) throw failed("writing the file failed");
  }
  std::error_code ec;
  fs::rename(partial.path(), path, ec);
  if (ec) throw failed(fmt::format("cannot rename it to '{}': {}", path.string(), ec.message()));
  partial.release();

  // The sidecar follows the data: after a failure here the HDF5 file is still complete.
  std::vector<std::string> names;
  for (const SetResult& r : sets) names.push_back(layout::set_name(r.set_index));
  XdmfFieldGrid grid;
  if (!sets.empty()) {
    const VectorField& f = sets.front().field;
    grid = {f.nx, f.ny, f.nz, f.origin, f.spacing};
  }
  write_text_atomically(ResultsWriter::sidecar_path(path),
                        xdmf_for_results(path.filename().string(), grid, names, !sets.empty()));
}

ResultsWriter::ResultsWriter(const fs::path& path, const ResultsInfo& info, const ResultsWriterOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.info = info;
  m.info.software_version = software_version();
  m.created_utc = utc_now_iso8601();
  if (!(info.voxel_size_mm > 0))
    throw bad_input(fmt::format("results file '{}': voxel size {} mm must be > 0", path.string(), info.voxel_size_mm));
  std::error_code ec;
  const bool resume = !options.overwrite && fs::exists(path, ec);
  check_output_path(path, true, "results");
  if (!resume) return;
  const ResultsReader existing(path);
  const ResultsInfo& old = existing.info();
  if (old.session_identity != info.session_identity)
    throw bad_input(fmt::format("results file '{}' belongs to another session ('{}', identity {}), not to '{}' "
                                "(identity {}); choose another output file, or --overwrite to replace it",
                                path.string(), old.session_path, old.session_identity, info.session_path,
                                info.session_identity));
  if (old.parameters_json != (info.parameters_json.empty() ? std::string("{}") : info.parameters_json))
    throw bad_input(fmt::format("results file '{}' was made with other processing parameters, so its sets cannot be "
                                "resumed; choose another output file, or --overwrite to replace it.\n  in the file: "
                                "{}\n  this run:    {}",
                                path.string(), old.parameters_json, info.parameters_json));
  if (old.voxel_size_mm != info.voxel_size_mm)
    throw bad_input(fmt::format("results file '{}' was made on {} mm voxels, this run uses {} mm; choose another "
                                "output file, or --overwrite",
                                path.string(), old.voxel_size_mm, info.voxel_size_mm));
  m.sets = existing.read_all_sets();
  m.resumed = m.sets.size();
}

ResultsWriter::~ResultsWriter() = default;

bool ResultsWriter::has_set(std::uint64_t set_index) const {
  return std::any_of(impl_->sets.begin(), impl_->sets.end(),
                     [&](const SetResult& r) { return r.set_index == set_index; });
}
const std::vector<SetResult>& ResultsWriter::sets() const { return impl_->sets; }
std::uint64_t ResultsWriter::resumed_sets() const { return impl_->resumed; }
const fs::path& ResultsWriter::path() const { return impl_->path; }

fs::path ResultsWriter::sidecar_path(const fs::path& results_file) {
  return fs::path(results_file).replace_extension(".xdmf");
}

void ResultsWriter::add(SetResult set) {
  Impl& m = *impl_;
  if (has_set(set.set_index))
    throw bad_input(fmt::format("results file '{}' already holds set {}", m.path.string(), set.set_index));
  const VectorField& f = set.field;
  if (f.displacement.size() != f.count() || f.status.size() != f.count() || f.peak.size() != f.count())
    throw bad_input(fmt::format("set {}: the vector field's arrays do not match its {} x {} x {} nodes",
                                set.set_index, f.nx, f.ny, f.nz));
  if (set.completed_utc.empty()) set.completed_utc = utc_now_iso8601();
  m.sets.push_back(std::move(set));
  try {
    EnsembleStatistics::compute(m.sets, m.info.voxel_size_mm);  // shape and dt checks before any write
    m.write_file();
  } catch (...) {
    m.sets.pop_back();
    throw;
  }
}

void ResultsWriter::write() { impl_->write_file(); }

}  // namespace tomorig::storage
