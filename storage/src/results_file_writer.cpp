// ResultsWriter, format version 2: the file and its (empty) layout are created through
// "<path>.partial" and a rename; then every add() appends one row to each /sets dataset in place
// under HDF5 SWMR, whose flush ordering keeps the file readable if the process dies at any
// moment. Per set, in this order, each step flushed before the next:
//   1. the row's data (fields, dt, time, report) and /statistics/sets = 0 (statistics stale);
//   2. /sets/complete[row] = 1 (the set now counts) and the new statistics;
//   3. /statistics/sets = the number of sets.
// An append therefore costs O(set): earlier rows are never rewritten. A file left by a crash
// (its superblock still says "open for writing") or of version 1 is copied once, set by set,
// into a fresh file when a run resumes it (O(file) once per resume, never per set).
#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <type_traits>
#include <vector>

#include <sys/resource.h>
#include <sys/statvfs.h>

#include <fmt/format.h>

#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "output_lock.h"
#include "tomorig/storage/output_path.h"
#include "partial_file.h"
#include "results_file_create.h"
#include "results_file_layout.h"
#include "results_file_open.h"
#include "results_file_rows.h"
#include "results_layout.h"
#include "results_xdmf.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/results_file.h"
#include "utc_time.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace layout = results_layout;
namespace v2 = results_layout_v2;
using namespace results_detail;
namespace {

using Clock = std::chrono::steady_clock;

static_assert(sizeof(Vec3f) == 3 * sizeof(float) && std::is_standard_layout_v<Vec3f>);
static_assert(sizeof(Vec3d) == 3 * sizeof(double) && std::is_standard_layout_v<Vec3d>);
static_assert(sizeof(VectorStatus) == 1);

// The sidecar lists every set, so rewriting it is O(file): at most this often while appending.
constexpr double kSidecarSeconds = 10.0;

void write_bytes(const fs::path& path, const std::vector<char>& bytes, PartialFile& partial, const char* what) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    throw runtime_error(fmt::format("cannot create {} '{}' (is folder '{}' writable?)", what, path.string(),
                                    path.parent_path().string()));
  partial.arm();
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw runtime_error(fmt::format("writing {} '{}' failed (is the disk full?)", what, path.string()));
}

void write_text_atomically(const fs::path& path, const std::string& text) {
  PartialFile partial(fs::path(path).concat(".partial"));
  write_bytes(partial.path(), std::vector<char>(text.begin(), text.end()), partial, "XDMF file");
  std::error_code ec;
  fs::rename(partial.path(), path, ec);
  if (ec)
    throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", partial.path().string(), path.string(), ec.message()));
  partial.release();
}

}  // namespace

struct ResultsWriter::Impl {
  OutputLock lock;  // held for the writer's life: one writer per results file
  fs::path path;
  ResultsInfo info;
  std::string created_utc;
  std::vector<std::uint64_t> indices;  // ascending
  std::uint64_t resumed = 0;
  EnsembleAccumulator stats{1.0};
  std::optional<FieldShape> shape;      // of the sets, once known
  bool file_exists = false;             // a file of this writer (or resumed) is under `path`
  bool file_has_layout = false;         // ... with its /sets rows
  std::optional<OpenFile> open;         // while appending
  std::optional<Clock::time_point> sidecar_written;

  [[noreturn]] void write_failed(const std::string& why) const {
    throw runtime_error(fmt::format("writing results file '{}' failed (is the disk full?): {}; the file still holds "
                                    "the {} sets finished before",
                                    path.string(), why, indices.size()));
  }
  void create(const std::optional<FieldShape>& with_shape, const ResultsReader* copy_from);
  void ensure_open();
  static void append_row(OpenFile& f, const SetResult& r, double voxel_size_mm);
  void write_statistics(OpenFile& f, const EnsembleStatistics& s);
  void write_sidecar();
  void abandon_after_failure() noexcept;
  bool abandoned = false;  // a write failed: never append to that file in place again
  // A set was added after one of a higher index (a resumed file's gaps, sets from several MPI
  // ranks): the running statistics then differ in the last bits from those of the sets in index
  // order, so close() recomputes them in that order, the order a single uninterrupted run adds.
  bool out_of_order = false;
  void restate_statistics_in_set_order();
  std::function<void()> after_room_check;  // ResultsWriterOptions: a test's disk filler
};

// Creates the file under `path` through "<path>.partial" and a rename; with `copy_from`, the
// finished sets of that (older or crashed) file are copied into it first, one at a time.
void ResultsWriter::Impl::create(const std::optional<FieldShape>& with_shape, const ResultsReader* copy_from) {
  h5::silence_errors();
  PartialFile partial(fs::path(path).concat(".partial"));
  std::uintmax_t needed = info.parameters_json.size() + kMetadataRoom;
  if (with_shape) {
    const std::size_t nodes = static_cast<std::size_t>(with_shape->nx) * with_shape->ny * with_shape->nz;
    needed = layout_bytes(nodes, info);
    if (copy_from) needed += copy_from->set_indices().size() * (nodes * 29 + 4096);
  }
  try {
    require_room(partial.path(), 0, needed, "creating the results file");
  } catch (const Error& e) {
    write_failed(e.what());
  }
  try {
    partial.arm();
    create_new_file(partial.path(), info, created_utc, with_shape);
  } catch (const h5::Failure& failure) {
    write_failed(failure.what());
  }
  if (with_shape) {
    std::optional<OpenFile> f;
    try {
      f = OpenFile::open(partial.path());
      if (!f) h5::fail("cannot open for appending", partial.path().string());
      if (copy_from) {
        for (const std::uint64_t i : copy_from->set_indices()) {
          // A set whose write failed may have reached the file; it is not counted, so not copied.
          if (!std::binary_search(indices.begin(), indices.end(), i)) continue;
          append_row(*f, copy_from->read_set(i), info.voxel_size_mm);
          const std::uint8_t one = 1;
          f->complete.write_rows(f->next_row - 1, 1, H5T_NATIVE_UINT8, &one);
        }
        if (stats.sets() > 0) {
          write_statistics(*f, stats.result());
          const std::uint64_t n = stats.sets();
          write_whole(f->stats_sets.get(), H5T_NATIVE_UINT64, &n, "/statistics/sets");
        }
      }
      f->flush(partial.path().string());
      if (f->close() < 0) h5::fail("cannot close", partial.path().string());
    } catch (const h5::Failure& failure) {
      if (f) f->close();
      write_failed(failure.what());
    }
  }
  std::error_code ec;
  fs::rename(partial.path(), path, ec);
  if (ec) write_failed(fmt::format("cannot rename '{}' to it: {}", partial.path().string(), ec.message()));
  partial.release();
  file_exists = true;
  file_has_layout = with_shape.has_value();
}

void ResultsWriter::Impl::ensure_open() {
  if (open) return;
  h5::silence_errors();
  if (!abandoned) {
    try {
      open = OpenFile::open(path);
    } catch (const h5::Failure& failure) {
      write_failed(failure.what());
    }
    if (open) return;
  }
  // HDF5 refuses to append: the file was left by a writer that died, or by a write that failed.
  // Copy its finished sets into a fresh file (a reader opens such a file in SWMR mode).
  {
    const ResultsReader old(path);
    create(shape, &old);
  }
  try {
    open = OpenFile::open(path);
  } catch (const h5::Failure& failure) {
    write_failed(failure.what());
  }
  if (!open) write_failed("HDF5 cannot open the file for appending: " + h5::error_stack_text());
  abandoned = false;
}

void ResultsWriter::Impl::append_row(OpenFile& f, const SetResult& r, double voxel_size_mm) {
  const hsize_t row = f.next_row;
  for (h5::RowDataset* d : f.rows()) d->grow_to(row + 1);
  f.next_row = row + 1;
  const VectorField& field = r.field;
  f.displacement.write_rows(row, 1, H5T_NATIVE_FLOAT, field.displacement.data());
  std::vector<float> velocity(3 * field.count());
  const double to_velocity = velocity_m_per_s(1.0, voxel_size_mm, r.dt_ns);
  for (std::size_t i = 0; i < field.count(); ++i) {
    const Vec3f& d = field.displacement[i];
    velocity[3 * i] = static_cast<float>(d.x * to_velocity);
    velocity[3 * i + 1] = static_cast<float>(d.y * to_velocity);
    velocity[3 * i + 2] = static_cast<float>(d.z * to_velocity);
  }
  f.velocity.write_rows(row, 1, H5T_NATIVE_FLOAT, velocity.data());
  f.status.write_rows(row, 1, H5T_NATIVE_UINT8, field.status.data());
  f.peak.write_rows(row, 1, H5T_NATIVE_FLOAT, field.peak.data());
  f.set_index.write_rows(row, 1, H5T_NATIVE_UINT64, &r.set_index);
  f.dt.write_rows(row, 1, H5T_NATIVE_INT64, &r.dt_ns);
  f.seconds.write_rows(row, 1, H5T_NATIVE_DOUBLE, &r.seconds);
  std::array<char, v2::kUtcBytes> utc{};
  std::memcpy(utc.data(), r.completed_utc.data(), std::min(r.completed_utc.size(), utc.size() - 1));
  const h5::Datatype type = utc_type();
  f.completed.write_rows(row, 1, type.get(), utc.data());
  const std::string report = r.report_json.empty() ? std::string("{}") : r.report_json;
  const std::array<std::uint64_t, 2> span{f.report_text.rows(), report.size()};
  f.report_text.grow_to(span[0] + span[1]);
  if (!report.empty()) f.report_text.write_rows(span[0], span[1], H5T_NATIVE_UINT8, report.data());
  f.report_span.write_rows(row, 1, H5T_NATIVE_UINT64, span.data());
}

void ResultsWriter::Impl::write_statistics(OpenFile& f, const EnsembleStatistics& s) {
  write_whole(f.valid_count.get(), H5T_NATIVE_UINT32, s.valid_count.data(), "/statistics/valid_count");
  write_whole(f.mean_displacement.get(), H5T_NATIVE_DOUBLE, s.mean_displacement_voxel.data(),
              "/statistics/mean_displacement_voxel");
  write_whole(f.mean_velocity.get(), H5T_NATIVE_DOUBLE, s.mean_velocity.data(), "/statistics/mean_velocity_m_s");
  write_whole(f.rms_velocity.get(), H5T_NATIVE_DOUBLE, s.rms_velocity.data(), "/statistics/rms_velocity_m_s");
  write_whole(f.reynolds.get(), H5T_NATIVE_DOUBLE, s.reynolds_stress.data(), "/statistics/reynolds_stress_m2_s2");
}

void ResultsWriter::Impl::write_sidecar() {
  XdmfFieldGrid grid;
  if (shape) grid = {shape->nx, shape->ny, shape->nz, shape->origin, shape->spacing};
  write_text_atomically(ResultsWriter::sidecar_path(path),
                        xdmf_for_result_rows(path.filename().string(), grid, open ? open->committed
                                                                                  : std::vector<XdmfSetRow>{},
                                             open ? open->next_row : 0, open && !indices.empty()));
  sidecar_written = Clock::now();
}

// After a failed write. HDF5 1.10 cannot close a file whose metadata it could not flush: the
// failed H5Fclose leaves the file half torn down, and the library crashes when it tries again at
// exit. So the failed file is never closed: its identifiers get one more reference each and are
// left open (HDF5 flushes what it can at exit). Everything flushed before the failure, i.e. every
// finished set, is on disk already, and the file's superblock still marks it as being written in
// SWMR mode, which readers accept. The next add() copies the finished sets into a fresh file.
void ResultsWriter::Impl::abandon_after_failure() noexcept {
  if (!open) return;
  H5Iinc_ref(open->file.get());
  for (h5::RowDataset* r : open->rows()) r->keep_open();
  open->report_text.keep_open();
  for (h5::Dataset* d : {&open->stats_sets, &open->valid_count, &open->mean_displacement, &open->mean_velocity,
                         &open->rms_velocity, &open->reynolds})
    if (d->valid()) H5Iinc_ref(d->get());
  open->close();
  open.reset();
  abandoned = true;
}

ResultsWriter::ResultsWriter(const fs::path& path, const ResultsInfo& info, const ResultsWriterOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.info = info;
  m.after_room_check = options.after_room_check;
  m.info.software_version = software_version();
  m.created_utc = utc_now_iso8601();
  m.stats = EnsembleAccumulator(info.voxel_size_mm);
  if (!(info.voxel_size_mm > 0))
    throw bad_input(fmt::format("results file '{}': voxel size {} mm must be > 0", path.string(), info.voxel_size_mm));
  check_output_path(path, true, "results");
  m.lock = OutputLock::acquire(path, "results");  // before the file is looked at: its content is ours now
  std::error_code ec;
  const bool resume = !options.overwrite && fs::exists(path, ec);
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
  // One set at a time: the statistics are rebuilt without holding the file in memory.
  for (const std::uint64_t i : existing.set_indices()) {
    const SetResult r = existing.read_set(i);
    m.stats.add(r);
    if (!m.shape) m.shape = shape_of(r.field);
    m.indices.push_back(i);
  }
  m.resumed = m.indices.size();
  m.file_exists = true;
  m.file_has_layout = existing.format_version() == v2::kFormatVersion && m.shape.has_value();
  if (existing.format_version() != v2::kFormatVersion && m.shape) {
    // A version-1 file: rewritten once in the current layout, so that sets can be appended.
    m.create(m.shape, &existing);
  }
}

ResultsWriter::~ResultsWriter() {
  try {
    close();
  } catch (...) {
    impl_->abandon_after_failure();  // the sets written so far are safe; the sidecar may lag
  }
}

bool ResultsWriter::has_set(std::uint64_t set_index) const {
  return std::binary_search(impl_->indices.begin(), impl_->indices.end(), set_index);
}
std::uint64_t ResultsWriter::set_count() const { return impl_->indices.size(); }
std::vector<std::uint64_t> ResultsWriter::set_indices() const { return impl_->indices; }
std::uint64_t ResultsWriter::resumed_sets() const { return impl_->resumed; }
EnsembleStatistics ResultsWriter::statistics() const { return impl_->stats.result(); }
const fs::path& ResultsWriter::path() const { return impl_->path; }

fs::path ResultsWriter::sidecar_path(const fs::path& results_file) {
  return fs::path(results_file).replace_extension(".xdmf");
}

void ResultsWriter::add(const SetResult& given) {
  Impl& m = *impl_;
  if (has_set(given.set_index))
    throw bad_input(fmt::format("results file '{}' already holds set {}", m.path.string(), given.set_index));
  m.stats.check(given);  // shape and dt, before anything is written
  const SetResult* set = &given;
  SetResult stamped;
  if (given.completed_utc.empty()) {
    stamped = given;
    stamped.completed_utc = utc_now_iso8601();
    set = &stamped;
  }
  if (!m.file_has_layout) {
    m.shape = shape_of(set->field);
    m.create(m.shape, nullptr);  // the file holds no set yet: O(1)
  }
  m.ensure_open();
  {
    std::error_code ec;
    const auto size = fs::file_size(m.path, ec);
    try {
      require_room(m.path, ec ? 0 : size, set_bytes(*set), fmt::format("set {}", set->set_index));
    } catch (const Error& e) {
      m.write_failed(e.what());
    }
  }
  if (m.after_room_check) m.after_room_check();
  EnsembleAccumulator updated = m.stats;
  updated.add(*set);
  h5::silence_errors();
  try {
    OpenFile& f = *m.open;
    const std::string where = m.path.string();
    const std::uint64_t stale = 0;
    Impl::append_row(f, *set, m.info.voxel_size_mm);
    write_whole(f.stats_sets.get(), H5T_NATIVE_UINT64, &stale, "/statistics/sets");
    f.flush(where);
    const std::uint8_t one = 1;
    f.complete.write_rows(f.next_row - 1, 1, H5T_NATIVE_UINT8, &one);  // from here on the set counts
    f.commit(set->set_index, f.next_row - 1);
    m.write_statistics(f, updated.result());
    f.flush(where);
    const std::uint64_t n = updated.sets();
    write_whole(f.stats_sets.get(), H5T_NATIVE_UINT64, &n, "/statistics/sets");
    f.flush(where);
  } catch (const h5::Failure& failure) {
    // The set may or may not have reached the file; it is not counted here, and the next add()
    // reopens the file (copying its finished sets if HDF5 left it marked as open).
    m.abandon_after_failure();
    m.write_failed(failure.what());
  }
  m.stats = std::move(updated);
  if (!m.indices.empty() && set->set_index < m.indices.back()) m.out_of_order = true;
  m.indices.insert(std::upper_bound(m.indices.begin(), m.indices.end(), set->set_index), set->set_index);
  if (!m.sidecar_written || std::chrono::duration<double>(Clock::now() - *m.sidecar_written).count() >= kSidecarSeconds)
    m.write_sidecar();
}

void ResultsWriter::write() {
  Impl& m = *impl_;
  if (!m.file_exists) m.create(std::nullopt, nullptr);
  if (!m.indices.empty()) m.ensure_open();  // the sidecar lists the sets' rows
  m.write_sidecar();
}

// Reads the finished sets back one at a time, in index order, and writes their statistics with
// the same three flushed steps as add(): O(file) once, only for a file whose sets came out of order.
void ResultsWriter::Impl::restate_statistics_in_set_order() {
  const std::string where = path.string();
  try {
    open->flush(where);
  } catch (const h5::Failure& failure) {
    abandon_after_failure();
    write_failed(failure.what());
  }
  if (open->close() < 0) {
    open.reset();
    write_failed("cannot close it: " + h5::error_stack_text());
  }
  open.reset();
  EnsembleAccumulator ordered(info.voxel_size_mm);
  {
    const ResultsReader finished(path);
    for (const std::uint64_t i : finished.set_indices())
      if (std::binary_search(indices.begin(), indices.end(), i)) ordered.add(finished.read_set(i));
  }
  ensure_open();
  h5::silence_errors();
  try {
    OpenFile& f = *open;
    const std::uint64_t stale = 0, n = ordered.sets();
    write_whole(f.stats_sets.get(), H5T_NATIVE_UINT64, &stale, "/statistics/sets");
    f.flush(where);
    write_statistics(f, ordered.result());
    f.flush(where);
    write_whole(f.stats_sets.get(), H5T_NATIVE_UINT64, &n, "/statistics/sets");
    f.flush(where);
  } catch (const h5::Failure& failure) {
    abandon_after_failure();
    write_failed(failure.what());
  }
  stats = std::move(ordered);
  out_of_order = false;
}

void ResultsWriter::close() {
  Impl& m = *impl_;
  if (!m.open) return;
  h5::silence_errors();
  if (m.out_of_order) m.restate_statistics_in_set_order();
  const std::string where = m.path.string();
  try {
    m.open->flush(where);
  } catch (const h5::Failure& failure) {
    m.abandon_after_failure();
    m.write_failed(failure.what());
  }
  m.write_sidecar();
  if (m.open->close() < 0) {
    m.open.reset();
    m.write_failed("cannot close it: " + h5::error_stack_text());
  }
  m.open.reset();
}

}  // namespace tomorig::storage
