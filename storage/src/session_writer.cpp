// SessionWriter: creates the layout of docs/file-formats.md in "<path>.partial", appends
// sets, and renames the file to <path> on finish().
#include <sys/statvfs.h>

#include <array>
#include <chrono>
#include <mutex>
#include <optional>
#include <utility>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>

#include "compression.h"
#include "direct_write_driver.h"
#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "output_lock.h"
#include "tomorig/storage/output_path.h"
#include "partial_file.h"
#include "quicklook_rows.h"
#include "session_layout.h"
#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"
#include "tomorig/core/version.h"
#include "tomorig/storage/session_cameras.h"
#include "tomorig/storage/session_file.h"
#include "utc_time.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

// An id becomes an HDF5 link name and part of file names: one rule for every id (core/camera_id.h).
void check_object_name(const std::string& id, const std::string& what, const fs::path& file) {
  require_valid_camera_id(id, fmt::format("session '{}', {}", file.string(), what));
}

}  // namespace

void check_session_cameras(const std::vector<SessionCamera>& cameras, const fs::path& file) {
  if (cameras.empty()) throw bad_input(fmt::format("session '{}' needs at least one camera", file.string()));
  if (cameras.size() > layout::kMaxCameras)
    throw bad_input(fmt::format("session '{}' would have {} cameras; a session holds at most {}", file.string(),
                                cameras.size(), layout::kMaxCameras));
  std::unordered_set<std::string> seen;
  for (const auto& c : cameras) {
    check_object_name(c.id, "camera", file);
    if (!seen.insert(c.id).second)
      throw bad_input(fmt::format("session '{}': camera id '{}' appears twice", file.string(), c.id));
    if (c.width <= 0 || c.height <= 0 || c.width > layout::kMaxImageSide || c.height > layout::kMaxImageSide)
      throw bad_input(fmt::format("session '{}': camera {} has size {} x {}; width and height must be 1 to {}",
                                  file.string(), c.id, c.width, c.height, layout::kMaxImageSide));
    const std::uint64_t frame_bytes = static_cast<std::uint64_t>(c.width) * static_cast<std::uint64_t>(c.height) *
                                      bytes_per_sample(sample_type_of(c.pixel_format));
    if (frame_bytes > layout::kMaxFrameBytes)
      throw bad_input(fmt::format("session '{}': camera {} frames of {} x {} {} take {} bytes; an HDF5 chunk (one "
                                  "frame) holds at most {}",
                                  file.string(), c.id, c.width, c.height, to_string(c.pixel_format), frame_bytes,
                                  layout::kMaxFrameBytes));
  }
}

namespace {


// A "<path>.partial" that exists before this writer starts was left by a writer that never
// finished: a live recording keeps every set it flushed there. It is evidence, never replaced.
[[noreturn]] void refuse_left_over_partial(const fs::path& partial, const fs::path& final_path) {
  const std::string p = partial.string();
  const fs::path kept = fs::path(final_path).replace_extension("").concat("-recovered").concat(
      final_path.extension().string());
  throw bad_input(fmt::format(
      "'{}' already exists: an earlier recording into '{}' did not finish (it was killed, crashed or lost power) and "
      "may hold recorded sets, so tomorig never replaces it, not even with --overwrite. See what it holds: "
      "tomorig inspect '{}'. To keep it: mv '{}' '{}' (other HDF5 tools may then need: h5clear -s '{}'). To "
      "discard it: rm '{}'. Then run again.",
      p, final_path.string(), p, p, kept.string(), kept.string(), p));
}

std::string describe_image(const Image& image) {
  return fmt::format("{} x {} {}", image.width(), image.height(), to_string(image.type()));
}

}  // namespace

struct SessionWriter::Impl {
  struct CameraStream {
    SessionCamera camera;
    h5::GrowingDataset frames;
    hid_t mem_type = H5T_NATIVE_UINT8;
    std::array<hsize_t, 4> count{};  // one frame: {1, 1, height, width}
  };

  Impl(const fs::path& path, const SessionInfo& info, const SessionWriterOptions& options);

  void create_layout(const SessionInfo& info);
  void create_camera(const SessionCamera& camera, std::size_t index, hid_t cameras_group);
  void create_set_datasets();
  // /quicklook and its empty tables (quicklook_record.h).
  void create_quicklook_datasets();
  void write_quicklook(const QuickLookRecord& record);
  // Checks every frame of `set` and fills frames_/timestamps_/present_; throws bad_input
  // before anything is written.
  void collect(const FrameSet& set);
  void write_collected(const FrameSet& set);
  std::size_t camera_index(const std::string& id) const;
  h5::Group ensure_group(hid_t parent, const char* name, const std::string& where);
  void require_open(const char* action) const;
  [[noreturn]] void fail_write(const std::string& action, const h5::Failure& failure);
  // The HDF5 side of write_truth / write_truth_set (a live recording defers them to finish()).
  void store_truth(const SessionTruth& truth);
  void store_truth_set(std::uint64_t set_index, const TruthSet& truth);
  void flush_if_due();
  // After a failed write (a full disk): shrinks /sets/trigger_index back to the sets of the
  // last successful flush, best effort, so that a reader of the kept partial file never counts
  // a set whose pixels may not have reached the disk. Never throws.
  void roll_back_unflushed() noexcept;
  // Throws DiskFullError if the collected set, the deferred truth and the reserve do not fit.
  void require_disk_room() const;
  // Live recordings: reopens the closed file without SWMR, marks it complete and writes the
  // truth held back while recording.
  void complete_live_file();

  // Declaration order matters: members are destroyed in reverse, so every dataset is closed,
  // then the file, then `partial` deletes the file if it was not finished, and only then is
  // the name unlocked for another writer.
  OutputLock lock;
  PartialFile partial;
  fs::path final_path;
  SessionWriterOptions options;
  h5::File file;
  std::vector<CameraStream> streams;
  std::unordered_map<std::string, std::size_t> index_of;
  h5::GrowingDataset trigger_index, trigger_timestamp, dt, frame_timestamp, frame_present;
  h5::GrowingDataset quicklook_set_index, quicklook_sets, quicklook_cameras;
  bool quicklook_created = false;
  std::uint64_t quicklook_rows = 0;
  std::vector<float> quicklook_row_;  // scratch: one set's row, then its cameras' rows
  // append() runs on the recorder's thread, append_quicklook() on a quick-look stage's: this
  // keeps the writer's state (counts, flush times, datasets) consistent between them.
  std::mutex mutex;

  // Per-set scratch, reused so that append() does not allocate in the steady state.
  std::vector<const Frame*> frames_;        // [camera * 2 + exposure], null if missing
  std::vector<std::int64_t> timestamps_;    // same indexing
  std::vector<std::uint8_t> present_;       // same indexing
  std::vector<char> seen_;                  // per camera
  std::vector<std::byte> staging_;          // for images whose rows are not contiguous

  bool truth_written = false;
  std::unordered_set<std::uint64_t> truth_sets;
  // Live recordings cannot create objects once SWMR writing has started, so truth waits here.
  std::optional<SessionTruth> deferred_truth;
  std::vector<std::pair<std::uint64_t, TruthSet>> deferred_truth_sets;
  std::uint64_t sets_at_last_flush = 0;
  std::chrono::steady_clock::time_point last_flush = std::chrono::steady_clock::now();
  std::uint64_t sets = 0;
  bool finished = false;
  bool failed = false;
};

SessionWriter::Impl::Impl(const fs::path& path, const SessionInfo& info, const SessionWriterOptions& opts)
    : partial(fs::path(path).concat(".partial")), final_path(path), options(opts) {
  check_session_cameras(info.cameras, final_path);
  check_output_path(final_path, options.overwrite, "session");
  lock = OutputLock::acquire(final_path, "session");
  std::error_code ec;
  if (fs::exists(fs::symlink_status(partial.path(), ec))) refuse_left_over_partial(partial.path(), final_path);
  if (options.compression != Compression::none)
    require_filter(kBitshuffleFilterId, fmt::format("writing session '{}' with {} compression", final_path.string(),
                                                    to_string(options.compression)));

  // SEMI: closing the file fails if an object is still open, instead of silently leaving the
  // file open (and unflushed) until the last object closes; it catches handle leaks in finish().
  h5::PropertyList fapl(h5::check(H5Pcreate(H5P_FILE_ACCESS), "cannot create", "a file access list"));
  h5::check(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_SEMI), "cannot configure", "a file access list");
  // Frame chunks bypass the page cache (direct_write_driver.h says why); the file is ordinary HDF5.
  set_direct_write_driver(fapl.get());
  // SWMR needs the newest file format (HDF5 >= 1.10 reads it; so do h5py and MATLAB R2021b+).
  if (options.live)
    h5::check(H5Pset_libver_bounds(fapl.get(), H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "cannot configure",
              "a file access list");
  // EXCL: even if something created the partial file since the check above, it is not truncated.
  const hid_t id = H5Fcreate(partial.path().c_str(), H5F_ACC_EXCL, H5P_DEFAULT, fapl.get());
  if (id < 0)
    throw bad_input(fmt::format("cannot create session file '{}' (is folder '{}' writable?): {}",
                                partial.path().string(), partial.path().parent_path().string(),
                                h5::error_stack_text()));
  file = h5::File(id);
  partial.arm();

  try {
    create_layout(info);
  } catch (const h5::Failure& failure) {
    throw runtime_error(fmt::format("cannot create the layout of session '{}': {}", partial.path().string(),
                                    failure.what()));
  }
  if (options.live) {
    if (H5Fstart_swmr_write(file.get()) < 0)
      throw runtime_error(fmt::format("cannot start live (SWMR) writing of session '{}': {}", partial.path().string(),
                                      h5::error_stack_text()));
    // From here on the file is worth keeping whatever happens to this writer.
    partial.release();
  }
  const std::size_t n = streams.size();
  frames_.resize(2 * n);
  timestamps_.resize(2 * n);
  present_.resize(2 * n);
  seen_.resize(n);
}

void SessionWriter::Impl::create_layout(const SessionInfo& info) {
  const hid_t root = file.get();
  // Format version 2: every string fixed-length (see session_layout.h).
  h5::write_fixed_string_attr(root, layout::kAttrFormat, layout::kFormatName, "/");
  h5::write_int_attr(root, layout::kAttrFormatVersion, layout::kFormatVersion, H5T_STD_I32LE, "/");
  h5::write_fixed_string_attr(root, layout::kAttrSoftwareVersion,
                              info.software_version.empty() ? software_version() : info.software_version, "/");
  h5::write_fixed_string_attr(root, layout::kAttrCreatedUtc,
                              info.created_utc.empty() ? utc_now_iso8601() : info.created_utc, "/");
  h5::write_fixed_string_attr(root, layout::kAttrCompression, to_string(options.compression), "/");
  if (options.live) h5::write_int_attr(root, layout::kAttrRecordingComplete, 0, H5T_STD_I32LE, "/");
  h5::write_fixed_string_dataset(root, layout::kConfig, info.rig_config_toml, "/config");

  h5::Group cameras = h5::create_group(root, layout::kCameras, "/cameras");
  std::vector<std::string> order;
  for (const auto& c : info.cameras) order.push_back(c.id);
  h5::write_fixed_string_list_attr(cameras.get(), layout::kAttrOrder, order, "/cameras");
  for (std::size_t i = 0; i < info.cameras.size(); ++i) create_camera(info.cameras[i], i, cameras.get());
  create_set_datasets();
  if (options.live) create_quicklook_datasets();
}

void SessionWriter::Impl::create_camera(const SessionCamera& camera, std::size_t index, hid_t cameras_group) {
  const std::string where = layout::camera_path(camera.id);
  h5::Group group = h5::create_group(cameras_group, camera.id.c_str(), where);
  h5::write_int_attr(group.get(), layout::kAttrWidth, camera.width, H5T_STD_I32LE, where);
  h5::write_int_attr(group.get(), layout::kAttrHeight, camera.height, H5T_STD_I32LE, where);
  h5::write_fixed_string_attr(group.get(), layout::kAttrPixelFormat, to_string(camera.pixel_format), where);
  h5::write_double_attr(group.get(), layout::kAttrPixelPitch, camera.pixel_pitch_um, where);
  h5::write_int_attr(group.get(), layout::kAttrIndex, static_cast<std::int64_t>(index), H5T_STD_I32LE, where);

  h5::PropertyList dcpl(h5::check(H5Pcreate(H5P_DATASET_CREATE), "cannot create", where));
  add_compression_filter(dcpl.get(), options.compression, "writing session '" + final_path.string() + "'");
  const auto h = static_cast<hsize_t>(camera.height);
  const auto w = static_cast<hsize_t>(camera.width);
  h5::GrowingDataset::Options o;
  o.file_type = layout::file_sample_type(camera.pixel_format);
  o.record_shape = {2, h, w};
  o.chunk = {1, 1, h, w};  // one frame per chunk: a frame is written and read whole
  o.dcpl = dcpl.get();
  o.chunk_cache_bytes = h5::frame_chunk_cache_bytes(options.compression != Compression::none,
                                                     h * w * bytes_per_sample(sample_type_of(camera.pixel_format)));

  CameraStream stream;
  stream.camera = camera;
  stream.frames = h5::GrowingDataset(group.get(), layout::kFrames, layout::frames_path(camera.id), o);
  stream.mem_type = layout::memory_sample_type(sample_type_of(camera.pixel_format));
  stream.count = {1, 1, h, w};
  index_of.emplace(camera.id, streams.size());
  streams.push_back(std::move(stream));
}

void SessionWriter::Impl::create_set_datasets() {
  h5::Group group = h5::create_group(file.get(), layout::kSets, "/sets");
  const hsize_t n_cams = streams.size();
  auto make = [&](const char* name, hid_t type, std::vector<hsize_t> record_shape) {
    h5::GrowingDataset::Options o;
    o.file_type = type;
    o.record_shape = record_shape;
    o.chunk = {layout::kSetsPerChunk};
    o.chunk.insert(o.chunk.end(), record_shape.begin(), record_shape.end());
    return h5::GrowingDataset(group.get(), name, layout::sets_path(name), o);
  };
  trigger_index = make(layout::kTriggerIndex, H5T_STD_U64LE, {});
  trigger_timestamp = make(layout::kTriggerTimestamp, H5T_STD_I64LE, {});
  dt = make(layout::kDt, H5T_STD_I64LE, {});
  frame_timestamp = make(layout::kFrameTimestamp, H5T_STD_I64LE, {n_cams, 2});
  frame_present = make(layout::kFramePresent, H5T_STD_U8LE, {n_cams, 2});
}

void SessionWriter::Impl::create_quicklook_datasets() {
  h5::Group group = h5::create_group(file.get(), layout::kQuickLook, "/quicklook");
  const hsize_t n_cams = streams.size();
  auto make = [&](const char* name, hid_t type, std::vector<hsize_t> record_shape,
                  const std::vector<std::string_view>* columns) {
    h5::GrowingDataset::Options o;
    o.file_type = type;
    o.record_shape = record_shape;
    o.chunk = {layout::kSetsPerChunk};
    o.chunk.insert(o.chunk.end(), record_shape.begin(), record_shape.end());
    h5::GrowingDataset d(group.get(), name, layout::quicklook_path(name), o);
    if (columns != nullptr) {
      // Fixed-length, like every string of a format-2 session: a damaged variable-length
      // string's heap index can crash libhdf5 1.10 (docs/reliability.md).
      h5::Dataset opened = h5::open_dataset(group.get(), name, layout::quicklook_path(name));
      h5::write_fixed_string_list_attr(opened.get(), layout::kAttrColumns,
                                 std::vector<std::string>(columns->begin(), columns->end()),
                                 layout::quicklook_path(name));
    }
    return d;
  };
  const auto& set_columns = quicklook_set_columns();
  const auto& camera_columns = quicklook_camera_columns();
  quicklook_sets = make(layout::kQuickLookSets, H5T_IEEE_F32LE, {set_columns.size()}, &set_columns);
  quicklook_cameras =
      make(layout::kQuickLookCameras, H5T_IEEE_F32LE, {n_cams, camera_columns.size()}, &camera_columns);
  quicklook_set_index = make(layout::kQuickLookSetIndex, H5T_STD_U64LE, {}, nullptr);
  quicklook_row_.resize(std::max(set_columns.size(), camera_columns.size() * streams.size()));
  quicklook_created = true;
}

// The tables first and the set index last, as for the sets: a reader counts a row once all of
// it is there.
void SessionWriter::Impl::write_quicklook(const QuickLookRecord& record) {
  if (!quicklook_created) create_quicklook_datasets();
  const hsize_t index = quicklook_rows;
  const hsize_t n = index + 1;
  const std::size_t per_camera = quicklook_camera_columns().size();
  for (std::size_t c = 0; c < record.cameras.size(); ++c)
    detail::camera_row(record.cameras[c], std::span(quicklook_row_).subspan(c * per_camera, per_camera));
  quicklook_cameras.grow_to(n);
  quicklook_cameras.write_record(index, H5T_NATIVE_FLOAT, quicklook_row_.data());
  detail::set_row(record, quicklook_row_);
  quicklook_sets.grow_to(n);
  quicklook_sets.write_record(index, H5T_NATIVE_FLOAT, quicklook_row_.data());
  quicklook_set_index.grow_to(n);
  quicklook_set_index.write_record(index, H5T_NATIVE_UINT64, &record.set_index);
  quicklook_rows = n;
  if (options.live) flush_if_due();
}

std::size_t SessionWriter::Impl::camera_index(const std::string& id) const {
  const auto it = index_of.find(id);
  return it == index_of.end() ? streams.size() : it->second;
}

void SessionWriter::Impl::require_open(const char* action) const {
  if (finished)
    throw runtime_error(fmt::format("cannot {}: session '{}' is already finished", action, final_path.string()));
  if (failed)
    throw runtime_error(fmt::format("cannot {}: an earlier write to session '{}' failed", action,
                                    partial.path().string()));
}

void SessionWriter::Impl::fail_write(const std::string& action, const h5::Failure& failure) {
  failed = true;  // datasets may now disagree in length; the file must not be finished
  throw runtime_error(fmt::format("{} session '{}' failed: {}", action, partial.path().string(), failure.what()));
}

void SessionWriter::Impl::collect(const FrameSet& set) {
  std::fill(frames_.begin(), frames_.end(), nullptr);
  std::fill(timestamps_.begin(), timestamps_.end(), 0);
  std::fill(present_.begin(), present_.end(), 0);
  std::fill(seen_.begin(), seen_.end(), 0);
  for (std::size_t k = 0; k < set.cameras.size(); ++k) {
    const CameraFrames& frames = set.cameras[k];
    // Sets normally list cameras in session order; the map is the fallback.
    const std::size_t c = k < streams.size() && streams[k].camera.id == frames.camera_id
                              ? k
                              : camera_index(frames.camera_id);
    if (c == streams.size()) {
      std::string known;
      for (const auto& s : streams) known += (known.empty() ? "" : ", ") + s.camera.id;
      throw bad_input(fmt::format("set {} has frames for camera '{}', which is not in session '{}' (cameras: {})",
                                  sets, frames.camera_id, final_path.string(), known));
    }
    if (seen_[c]) throw bad_input(fmt::format("set {} lists camera {} twice", sets, frames.camera_id));
    seen_[c] = 1;
    const SessionCamera& camera = streams[c].camera;
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      const Frame& frame = frames[e];
      const std::size_t slot = 2 * c + static_cast<std::size_t>(e);
      timestamps_[slot] = frame.timestamp_ns;
      if (!frame.present()) continue;
      const Image& image = frame.image;
      if (image.width() != camera.width || image.height() != camera.height ||
          image.type() != sample_type_of(camera.pixel_format))
        throw bad_input(fmt::format("camera {}, set {}, frame {}: image is {} but session '{}' expects {} x {} {} "
                                    "({})",
                                    camera.id, sets, e == Exposure::A ? 'A' : 'B', describe_image(image),
                                    final_path.string(), camera.width, camera.height,
                                    to_string(sample_type_of(camera.pixel_format)), to_string(camera.pixel_format)));
      frames_[slot] = &frame;
      present_[slot] = frame.synchronised ? 1 : 2;  // 2: present, not exposed by this event (free-running)
    }
  }
}

// Order matters for readers of a live file and after a crash: the frames go first, then the
// per-set records, and /sets/trigger_index last, so a set counts (the shortest dataset decides)
// only once everything about it is on disk.
void SessionWriter::Impl::write_collected(const FrameSet& set) {
  const hsize_t index = sets;
  const hsize_t n = sets + 1;
  for (std::size_t c = 0; c < streams.size(); ++c) {
    CameraStream& s = streams[c];
    s.frames.grow_to(n);
    for (hsize_t e = 0; e < 2; ++e) {
      const Frame* frame = frames_[2 * c + e];
      if (frame == nullptr) continue;  // missing: its chunk is never allocated (reads as 0)
      const Image& image = frame->image;
      const std::byte* data = image.data();
      if (!image.contiguous()) {
        staging_.resize(image.size_bytes());
        image.copy_to(staging_);
        data = staging_.data();
      }
      const std::array<hsize_t, 4> offset{index, e, 0, 0};
      s.frames.write(offset, s.count, s.mem_type, data);
    }
  }
  frame_timestamp.grow_to(n);
  frame_timestamp.write_record(index, H5T_NATIVE_INT64, timestamps_.data());
  frame_present.grow_to(n);
  frame_present.write_record(index, H5T_NATIVE_UINT8, present_.data());
  dt.grow_to(n);
  dt.write_record(index, H5T_NATIVE_INT64, &set.dt_ns);
  trigger_timestamp.grow_to(n);
  trigger_timestamp.write_record(index, H5T_NATIVE_INT64, &set.trigger_timestamp_ns);
  trigger_index.grow_to(n);
  trigger_index.write_record(index, H5T_NATIVE_UINT64, &set.trigger_index);
  sets = n;
  if (options.live) flush_if_due();
}

void SessionWriter::Impl::roll_back_unflushed() noexcept {
  const std::uint64_t kept = options.live ? sets_at_last_flush : 0;
  try {
    trigger_index.grow_to(kept);  // the shortest dataset decides how many sets a reader sees
    H5Fflush(file.get(), H5F_SCOPE_LOCAL);
  } catch (...) {
    // The file may be past saving; the reader's own checks are the last line of defence.
  }
  sets = kept;
}

void SessionWriter::Impl::require_disk_room() const {
  std::uint64_t needed = options.disk_reserve_bytes;
  for (const Frame* frame : frames_)
    if (frame != nullptr) needed += frame->image.size_bytes();  // compressed data is never larger by much
  for (const auto& [index, truth] : deferred_truth_sets)
    needed += (truth.particles_a.size() + truth.particles_b.size()) * sizeof(Vec3d);
  struct statvfs disk {};
  const fs::path folder = partial.path().has_parent_path() ? partial.path().parent_path() : fs::path(".");
  if (statvfs(folder.c_str(), &disk) != 0) return;  // cannot tell: HDF5 will report a real failure
  const std::uint64_t available = static_cast<std::uint64_t>(disk.f_bavail) * disk.f_frsize;
  if (available >= needed) return;
  constexpr double MB = 1e6;
  throw DiskFullError(fmt::format(
      "the disk holding '{}' is full: {:.1f} MB free, but set {} needs {:.1f} MB including the reserve of {:.1f} MB "
      "kept for closing the file; nothing of set {} was written, the {} sets before it are kept",
      partial.path().string(), static_cast<double>(available) / MB, sets, static_cast<double>(needed) / MB,
      static_cast<double>(options.disk_reserve_bytes) / MB, sets, sets));
}

void SessionWriter::Impl::flush_if_due() {
  const auto now = std::chrono::steady_clock::now();
  // Multiples of every_sets, not "every_sets after the last flush": a flush by time in between
  // must not push the next one back (a slow start would leave set 10 unflushed at its line).
  const bool by_count =
      options.flush.every_sets > 0 && sets != sets_at_last_flush && sets % options.flush.every_sets == 0;
  const bool by_time = std::chrono::duration<double>(now - last_flush).count() >= options.flush.every_seconds;
  if (!by_count && !by_time) return;
  h5::check(H5Fflush(file.get(), H5F_SCOPE_LOCAL), "cannot flush", partial.path().string());
  sets_at_last_flush = sets;
  last_flush = now;
}

// /truth and its children are created on first use: write_truth and write_truth_set may be
// called in either order.
h5::Group SessionWriter::Impl::ensure_group(hid_t parent, const char* name, const std::string& where) {
  if (h5::link_exists(parent, name)) return h5::open_group(parent, name, where);
  return h5::create_group(parent, name, where);
}

SessionWriter::SessionWriter(const fs::path& path, const SessionInfo& info, const SessionWriterOptions& options) {
  h5::silence_errors();
  impl_ = std::make_unique<Impl>(path, info, options);
}

SessionWriter::~SessionWriter() = default;

void SessionWriter::append(const FrameSet& set) {
  h5::silence_errors();
  Impl& m = *impl_;
  const std::lock_guard lock(m.mutex);
  m.require_open("append a set");
  m.collect(set);
  if (m.options.disk_reserve_bytes > 0) m.require_disk_room();
  const std::uint64_t index = m.sets;
  try {
    m.write_collected(set);
  } catch (const h5::Failure& failure) {
    m.roll_back_unflushed();
    m.fail_write(fmt::format("writing set {} to", index), failure);
  }
}

void SessionWriter::append_quicklook(const QuickLookRecord& record) {
  h5::silence_errors();
  Impl& m = *impl_;
  const std::lock_guard lock(m.mutex);
  m.require_open("store quick-look numbers");
  if (record.cameras.size() != m.streams.size())
    throw bad_input(fmt::format("quick-look numbers of set {} are for {} cameras but session '{}' has {}",
                                record.set_index, record.cameras.size(), m.final_path.string(), m.streams.size()));
  try {
    m.write_quicklook(record);
  } catch (const h5::Failure& failure) {
    // Only /quicklook was touched, and its reader counts whole rows: the sets stay valid, so
    // the writer carries on (unlike a failed set).
    throw runtime_error(fmt::format("writing quick-look numbers of set {} to session '{}' failed: {}",
                                    record.set_index, m.partial.path().string(), failure.what()));
  }
}

void SessionWriter::write_truth(const SessionTruth& truth) {
  h5::silence_errors();
  Impl& m = *impl_;
  const std::lock_guard lock(m.mutex);
  m.require_open("write truth");
  if (m.truth_written)
    throw runtime_error(fmt::format("truth of session '{}' is already written", m.final_path.string()));
  std::unordered_set<std::string> seen;
  for (const auto& c : truth.cameras) {
    check_object_name(c.id, "truth camera", m.final_path);
    if (!seen.insert(c.id).second)
      throw bad_input(fmt::format("session '{}': truth camera id '{}' appears twice", m.final_path.string(), c.id));
  }
  if (m.options.live) {
    m.deferred_truth = truth;
  } else {
    try {
      m.store_truth(truth);
    } catch (const h5::Failure& failure) {
      m.fail_write("writing truth to", failure);
    }
  }
  m.truth_written = true;
}

void SessionWriter::Impl::store_truth(const SessionTruth& truth) {
  h5::Group group = ensure_group(file.get(), layout::kTruth, "/truth");
  h5::write_fixed_string_attr(group.get(), layout::kAttrCase, truth.case_name, "/truth");
  h5::write_fixed_string_attr(group.get(), layout::kAttrFlow, truth.flow_name, "/truth");
  h5::write_fixed_string_attr(group.get(), layout::kAttrFlowParameters, truth.flow_parameters, "/truth");
  h5::write_uint64_attr(group.get(), layout::kAttrSeed, truth.seed, "/truth");
  h5::write_double_attr(group.get(), layout::kAttrPpp, truth.ppp, "/truth");

  h5::Group cameras = ensure_group(group.get(), layout::kCameras, "/truth/cameras");
  std::vector<std::string> order;
  for (const auto& c : truth.cameras) order.push_back(c.id);
  h5::write_fixed_string_list_attr(cameras.get(), layout::kAttrOrder, order, "/truth/cameras");
  const hsize_t mat_dims[2] = {3, 3};
  const hsize_t vec_dims[1] = {3};
  for (const auto& c : truth.cameras) {
    const std::string where = "/truth/cameras/" + c.id;
    h5::Group g = h5::create_group(cameras.get(), c.id.c_str(), where);
    h5::write_fixed_string_attr(g.get(), layout::kAttrModel, c.model, where);
    h5::write_doubles_attr(g.get(), layout::kAttrK, c.K, mat_dims, where);
    h5::write_doubles_attr(g.get(), layout::kAttrR, c.R, mat_dims, where);
    const std::array<double, 3> t{c.t.x, c.t.y, c.t.z};
    h5::write_doubles_attr(g.get(), layout::kAttrT, t, vec_dims, where);
    h5::write_int_attr(g.get(), layout::kAttrWidth, c.width, H5T_STD_I32LE, where);
    h5::write_int_attr(g.get(), layout::kAttrHeight, c.height, H5T_STD_I32LE, where);
  }
}

void SessionWriter::write_truth_set(std::uint64_t set_index, const TruthSet& truth) {
  h5::silence_errors();
  Impl& m = *impl_;
  const std::lock_guard lock(m.mutex);
  m.require_open("write truth");
  if (m.truth_sets.contains(set_index))
    throw runtime_error(fmt::format("truth for set {} of session '{}' is already written", set_index,
                                    m.final_path.string()));
  if (m.options.live) {
    m.deferred_truth_sets.emplace_back(set_index, truth);
  } else {
    try {
      m.store_truth_set(set_index, truth);
    } catch (const h5::Failure& failure) {
      m.fail_write("writing truth to", failure);
    }
  }
  m.truth_sets.insert(set_index);
}

void SessionWriter::Impl::store_truth_set(std::uint64_t set_index, const TruthSet& truth) {
  static_assert(sizeof(Vec3d) == 3 * sizeof(double), "Vec3d is written as 3 packed doubles");
  h5::Group truth_group = ensure_group(file.get(), layout::kTruth, "/truth");
  h5::Group sets_group = ensure_group(truth_group.get(), layout::kSets, "/truth/sets");
  const std::string where = layout::truth_set_path(set_index);
  h5::Group g = h5::create_group(sets_group.get(), layout::truth_set_name(set_index).c_str(), where);
  for (const auto& [name, particles] : {std::pair{layout::kParticlesA, &truth.particles_a},
                                        std::pair{layout::kParticlesB, &truth.particles_b}}) {
    const hsize_t dims[2] = {particles->size(), 3};
    h5::write_dataset(g.get(), name, H5T_IEEE_F64LE, dims, H5T_NATIVE_DOUBLE, particles->data(), where + "/" + name);
  }
}

void SessionWriter::Impl::complete_live_file() {
  h5::PropertyList fapl(h5::check(H5Pcreate(H5P_FILE_ACCESS), "cannot create", "a file access list"));
  h5::check(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_SEMI), "cannot configure", "a file access list");
  file = h5::File(h5::check(H5Fopen(partial.path().c_str(), H5F_ACC_RDWR, fapl.get()), "cannot reopen",
                            partial.path().string()));
  h5::check(H5Adelete(file.get(), layout::kAttrRecordingComplete), "cannot update", "/recording_complete");
  h5::write_int_attr(file.get(), layout::kAttrRecordingComplete, 1, H5T_STD_I32LE, "/");
  if (deferred_truth) store_truth(*deferred_truth);
  for (const auto& [index, truth] : deferred_truth_sets) store_truth_set(index, truth);
  deferred_truth.reset();
  deferred_truth_sets.clear();
}

void SessionWriter::finish() {
  h5::silence_errors();
  Impl& m = *impl_;
  const std::lock_guard lock(m.mutex);
  m.require_open("finish");
  const std::string partial = m.partial.path().string();
  bool closed = true;
  for (auto& s : m.streams) closed &= s.frames.close() >= 0;
  for (auto* d : {&m.trigger_index, &m.trigger_timestamp, &m.dt, &m.frame_timestamp, &m.frame_present,
                  &m.quicklook_set_index, &m.quicklook_sets, &m.quicklook_cameras})
    closed &= d->close() >= 0;
  closed &= m.file.close() >= 0;  // flushes everything to disk
  if (closed && m.options.live) {
    // The live file is kept under its .partial name from here until the rename below.
    try {
      m.complete_live_file();
      closed = m.file.close() >= 0;
    } catch (const h5::Failure& failure) {
      m.failed = true;
      throw runtime_error(fmt::format("completing live session '{}' failed; the recorded sets remain readable in "
                                      "it: {}",
                                      partial, failure.what()));
    }
  }
  if (!closed) {
    m.failed = true;
    throw runtime_error(fmt::format("closing session '{}' failed, so it may be incomplete (is the disk full?): {}",
                                    partial, h5::error_stack_text()));
  }
  std::error_code ec;
  if (!m.options.overwrite && fs::exists(m.final_path, ec)) {
    m.failed = true;
    throw bad_input(fmt::format("session file '{}' appeared while it was being written; not replacing it",
                                m.final_path.string()));
  }
  fs::rename(m.partial.path(), m.final_path, ec);
  if (ec) {
    m.failed = true;
    throw runtime_error(fmt::format("cannot rename '{}' to '{}': {}", partial, m.final_path.string(), ec.message()));
  }
  m.partial.release();
  m.finished = true;
  m.lock = OutputLock();  // the file is complete under its name: another writer may now replace it
}

std::uint64_t SessionWriter::sets_written() const {
  const std::lock_guard lock(impl_->mutex);
  return impl_->sets;
}
const fs::path& SessionWriter::path() const { return impl_->final_path; }
const fs::path& SessionWriter::partial_path() const { return impl_->partial.path(); }

}  // namespace tomorig::storage
