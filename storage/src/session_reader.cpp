// SessionReader: opens a session file, validates its layout up front (so a bad file fails
// at open with one clear message instead of half-way through processing) and reads sets.
#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <unordered_set>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "compression.h"
#include "h5_attributes.h"
#include "h5_datasets.h"
#include "h5_error.h"
#include "h5_handle.h"
#include "h5_open.h"
#include "isolated_probe.h"
#include "quicklook_rows.h"
#include "session_layout.h"
#include "tomorig/core/camera_id.h"
#include "tomorig/core/error.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {
namespace fs = std::filesystem;
namespace {

struct CameraDataset {
  h5::Dataset frames;
  std::string where;
  hid_t mem_type = H5T_NATIVE_UINT8;
  SampleType sample_type = SampleType::u8;
  std::array<hsize_t, 4> count{};  // one frame
};

// An image whose buffer is not zero-filled first: HDF5 overwrites every byte.
Image uninitialised_image(int width, int height, SampleType type) {
  const std::size_t bytes = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * bytes_per_sample(type);
  std::shared_ptr<std::byte[]> buffer = std::make_shared_for_overwrite<std::byte[]>(bytes);
  std::byte* data = buffer.get();
  return Image::view(data, width, height, type, 0, std::move(buffer));
}

// Integer dataset types the frames may use, by pixel format.
void check_frame_type(hid_t dataset, const SessionCamera& camera, const std::string& where) {
  h5::Datatype type(h5::check(H5Dget_type(dataset), "cannot read the type of", where));
  const bool is_int = H5Tget_class(type.get()) == H5T_INTEGER;
  const std::size_t bits = 8 * H5Tget_size(type.get());
  const std::size_t wanted = 8 * bytes_per_sample(sample_type_of(camera.pixel_format));
  if (!is_int || bits != wanted || H5Tget_sign(type.get()) != H5T_SGN_NONE)
    throw h5::Failure(fmt::format("camera {}: frames are stored as {}, but pixel format {} needs unsigned {}-bit "
                                  "integers",
                                  camera.id, is_int ? fmt::format("{}-bit integers", bits) : "non-integers",
                                  to_string(camera.pixel_format), wanted));
}

// a * b, or nothing if it does not fit in 64 bits.
std::optional<std::uint64_t> checked_product(std::uint64_t a, std::uint64_t b) {
  if (a != 0 && b > std::numeric_limits<std::uint64_t>::max() / a) return std::nullopt;
  return a * b;
}

bool has_filters(hid_t dataset, const std::string& where) {
  h5::PropertyList dcpl(h5::check(H5Dget_create_plist(dataset), "cannot read the creation properties of", where));
  return h5::check(H5Pget_nfilters(dcpl.get()), "cannot read the filters of", where) > 0;
}

// An integer attribute that must lie in [low, high], checked before it is narrowed to int.
int read_bounded_int(hid_t object, const char* name, std::int64_t low, std::int64_t high, const std::string& where) {
  const std::int64_t value = h5::read_int_attr(object, name, where);
  if (value < low || value > high)
    throw h5::Failure(fmt::format("attribute '{}' of {} is {}; it must be {} to {}", name, where, value, low, high));
  return static_cast<int>(value);
}

// Camera ids of an 'order' attribute: each valid (core/camera_id.h) and none twice. A damaged
// or hand-made file listing one camera four times would otherwise show one camera's frames as
// four views.
void check_order(const std::vector<std::string>& order, const std::string& where) {
  if (order.size() > layout::kMaxCameras)
    throw h5::Failure(fmt::format("{} lists {} cameras; a session holds at most {}", where, order.size(),
                                  layout::kMaxCameras));
  std::unordered_set<std::string> seen;
  for (const std::string& id : order) {
    if (const auto problem = camera_id_problem(id))
      throw h5::Failure(fmt::format("{} lists camera id \"{}\", which is not allowed: it {}", where, printable(id),
                                    *problem));
    if (!seen.insert(id).second) throw h5::Failure(fmt::format("{} lists camera '{}' twice", where, id));
  }
}

}  // namespace

struct SessionReader::Impl {
  explicit Impl(const fs::path& path);

  // Everything wrong with the file's content is reported as bad input naming the file.
  [[noreturn]] void corrupt(const std::string& what) const {
    throw bad_input(fmt::format("session file '{}' is corrupt or truncated: {}", path.string(), what));
  }
  [[noreturn]] void invalid(const std::string& what) const {
    throw bad_input(fmt::format("session file '{}' is not a valid tomorig session: {}", path.string(), what));
  }

  void open_file();
  void read_root();
  void read_cameras();
  // Returns whether the dataset has any filter (compression).
  bool check_filters(hid_t dataset, const std::string& where) const;
  void read_sets();
  template <typename T>
  std::vector<T> read_set_dataset(hid_t group, const char* name, hid_t mem_type, std::vector<hsize_t> record_shape);
  void check_index(std::uint64_t set_index) const;
  // Throws corrupt() unless `bytes` more of memory is within what a file of this size may
  // make a reader allocate (session_layout.h).
  void require_memory(std::optional<std::uint64_t> bytes, const std::string& what) const;
  // Unfiltered datasets store every element written: fewer stored bytes than declared means
  // the extent was damaged (or never written). Filtered ones are bounded by require_memory.
  void require_stored(hid_t dataset, std::optional<std::uint64_t> bytes, const std::string& where) const;
  void check_frame_storage();
  h5::Group truth_sets_group() const;
  SessionTruth read_truth() const;
  TruthSet read_truth_set(std::uint64_t set_index, bool headers_only) const;
  std::vector<QuickLookRecord> read_quicklook() const;
  // For the isolated probe: the objects read later on demand (truth metadata, truth sets'
  // headers, the quick-look tables).
  void touch_lazily_read_objects() const;

  fs::path path;
  std::uint64_t file_bytes = 0;
  h5::File file;
  SessionInfo info;
  int format_version = 0;
  std::vector<CameraDataset> cameras;
  std::uint64_t sets = 0;
  std::vector<std::uint64_t> trigger_index;
  std::vector<std::int64_t> trigger_timestamp, dt;
  std::vector<std::int64_t> frame_timestamp;  // [set][camera][exposure]
  std::vector<std::uint8_t> frame_present;    // [set][camera][exposure]
  int missing = 0;
  int incomplete = 0;
  bool truth = false;
  // A live recording still being written or interrupted: datasets may differ in length by the
  // set in progress, and the sets are those every dataset holds.
  bool recording_complete = true;
};

SessionReader::Impl::Impl(const fs::path& p) : path(p) {
  open_file();
  try {
    read_root();
    read_cameras();
    read_sets();
    truth = h5::link_exists(file.get(), layout::kTruth);
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
}

void SessionReader::Impl::open_file() {
  file = h5::open_for_reading(path, "session file");
  std::error_code ec;
  file_bytes = fs::file_size(path, ec);
  if (ec) file_bytes = 0;
}

void SessionReader::Impl::require_memory(std::optional<std::uint64_t> bytes, const std::string& what) const {
  const std::uint64_t limit = std::max(layout::kRecordBytesFloor,
                                       checked_product(file_bytes, layout::kRecordBytesPerFileByte)
                                           .value_or(std::numeric_limits<std::uint64_t>::max()));
  if (!bytes || *bytes > limit)
    corrupt(fmt::format("{} would take {} of memory, more than a {}-byte file can hold (at most {} bytes); its "
                        "declared size is damaged",
                        what, bytes ? fmt::format("{} bytes", *bytes) : std::string("more than 2^64 bytes"),
                        file_bytes, limit));
}

void SessionReader::Impl::require_stored(hid_t dataset, std::optional<std::uint64_t> bytes,
                                         const std::string& where) const {
  if (has_filters(dataset, where)) return;
  const hsize_t stored = H5Dget_storage_size(dataset);
  if (!bytes || stored < *bytes)
    corrupt(fmt::format("{} declares {} bytes of data but the file stores {}", where,
                        bytes ? std::to_string(*bytes) : std::string("more than 2^64"), stored));
}

void SessionReader::Impl::read_root() {
  const hid_t root = file.get();
  if (!h5::has_attr(root, layout::kAttrFormat))
    invalid(fmt::format("it is an HDF5 file without the root attribute '{}' = '{}'", layout::kAttrFormat,
                        layout::kFormatName));
  const std::string format = h5::read_string_attr(root, layout::kAttrFormat, "/");
  if (format != layout::kFormatName)
    invalid(fmt::format("its root attribute '{}' is '{}', expected '{}'", layout::kAttrFormat, format,
                        layout::kFormatName));
  if (!h5::has_attr(root, layout::kAttrFormatVersion))
    invalid(fmt::format("the root attribute '{}' is missing", layout::kAttrFormatVersion));
  const std::int64_t version = h5::read_int_attr(root, layout::kAttrFormatVersion, "/");  // an integer, not 1.0
  if (version < layout::kOldestFormatVersion || version > layout::kFormatVersion)
    throw bad_input(fmt::format("session file '{}' has format version {}, but this tomorig reads versions {} to {}{}",
                                path.string(), version, layout::kOldestFormatVersion, layout::kFormatVersion,
                                version > layout::kFormatVersion ? ": update tomorig to read it" : ""));
  format_version = static_cast<int>(version);

  // Descriptive metadata: tolerated when absent, so that files assembled by hand stay readable.
  if (h5::has_attr(root, layout::kAttrSoftwareVersion))
    info.software_version = h5::read_string_attr(root, layout::kAttrSoftwareVersion, "/");
  if (h5::has_attr(root, layout::kAttrCreatedUtc))
    info.created_utc = h5::read_string_attr(root, layout::kAttrCreatedUtc, "/");
  if (h5::has_attr(root, layout::kAttrCompression)) {
    const std::string name = h5::read_string_attr(root, layout::kAttrCompression, "/");
    const auto compression = parse_compression(name);
    if (!compression) invalid(fmt::format("unknown compression '{}' (known: none, bitshuffle-lz4)", name));
    info.compression = *compression;
  }
  if (h5::link_exists(root, layout::kConfig))
    info.rig_config_toml = h5::read_string_dataset(root, layout::kConfig, "/config");
  if (h5::has_attr(root, layout::kAttrRecordingComplete))
    recording_complete = h5::read_int_attr(root, layout::kAttrRecordingComplete, "/") != 0;
}

void SessionReader::Impl::read_cameras() {
  if (!h5::link_exists(file.get(), layout::kCameras)) invalid("the group /cameras is missing");
  h5::Group group = h5::open_group(file.get(), layout::kCameras, "/cameras");
  const std::vector<std::string> order = h5::read_string_list_attr(group.get(), layout::kAttrOrder, "/cameras");
  if (order.empty()) invalid("/cameras lists no cameras");
  try {
    check_order(order, "/cameras 'order'");
  } catch (const h5::Failure& failure) {
    invalid(failure.what());
  }

  for (std::size_t position = 0; position < order.size(); ++position) {
    const std::string& id = order[position];
    const std::string where = layout::camera_path(id);
    if (!h5::link_exists(group.get(), id.c_str()))
      invalid(fmt::format("camera '{}' is listed in /cameras 'order' but {} is missing", id, where));
    h5::Group cam = h5::open_group(group.get(), id.c_str(), where);
    SessionCamera camera;
    camera.id = id;
    camera.width = read_bounded_int(cam.get(), layout::kAttrWidth, 1, layout::kMaxImageSide, where);
    camera.height = read_bounded_int(cam.get(), layout::kAttrHeight, 1, layout::kMaxImageSide, where);
    // The camera's place in the session: every per-camera record is indexed by it.
    if (h5::has_attr(cam.get(), layout::kAttrIndex)) {
      const std::int64_t index = h5::read_int_attr(cam.get(), layout::kAttrIndex, where);
      if (index != static_cast<std::int64_t>(position))
        invalid(fmt::format("camera {} has index {} but is listed at position {} in /cameras 'order'", id, index,
                            position));
    }
    const std::string format = h5::read_string_attr(cam.get(), layout::kAttrPixelFormat, where);
    const auto pixel_format = parse_pixel_format(format);
    if (!pixel_format)
      invalid(fmt::format("camera {} has pixel format '{}'; known formats: {}", id, format, supported_pixel_formats()));
    camera.pixel_format = *pixel_format;
    if (h5::has_attr(cam.get(), layout::kAttrPixelPitch))
      camera.pixel_pitch_um = h5::read_double_attr(cam.get(), layout::kAttrPixelPitch, where);

    CameraDataset ds;
    ds.where = layout::frames_path(id);
    ds.frames = h5::open_dataset(cam.get(), layout::kFrames, ds.where);
    const std::vector<hsize_t> dims = h5::dims_of(ds.frames.get(), ds.where);
    const bool filtered = check_filters(ds.frames.get(), ds.where);
    if (dims.size() != 4 || dims[1] != 2)
      invalid(fmt::format("{} should have shape [sets, 2, height, width] but has {} dimensions{}", ds.where,
                          dims.size(), dims.size() == 4 ? fmt::format(" with {} exposures", dims[1]) : ""));
    if (dims[2] != static_cast<hsize_t>(camera.height) || dims[3] != static_cast<hsize_t>(camera.width))
      invalid(fmt::format("camera {}: frames are {} x {} but the session says {} x {}", id, dims[3], dims[2],
                          camera.width, camera.height));
    check_frame_type(ds.frames.get(), camera, ds.where);
    const std::uint64_t frame_bytes = static_cast<std::uint64_t>(camera.width) *
                                      static_cast<std::uint64_t>(camera.height) *
                                      bytes_per_sample(sample_type_of(camera.pixel_format));
    if (frame_bytes > layout::kMaxFrameBytes)
      invalid(fmt::format("camera {} declares {} x {} {} frames of {} bytes; a frame is one HDF5 chunk, at most {} "
                          "bytes",
                          id, camera.width, camera.height, to_string(camera.pixel_format), frame_bytes,
                          layout::kMaxFrameBytes));
    // Reopened with a chunk cache suited to whole-frame reads (see frame_chunk_cache_bytes).
    ds.frames = h5::open_dataset(cam.get(), layout::kFrames,
                                 h5::frame_chunk_cache_bytes(filtered, dims[2] * dims[3] *
                                                                           bytes_per_sample(sample_type_of(camera.pixel_format))),
                                 ds.where);
    if (cameras.empty()) {
      sets = dims[0];
    } else if (!recording_complete) {
      sets = std::min<std::uint64_t>(sets, dims[0]);
    } else if (dims[0] != sets) {
      corrupt(fmt::format("camera {} holds {} sets but camera {} holds {}", id, dims[0], info.cameras.front().id,
                          sets));
    }
    ds.sample_type = sample_type_of(camera.pixel_format);
    ds.mem_type = layout::memory_sample_type(ds.sample_type);
    ds.count = {1, 1, dims[2], dims[3]};
    cameras.push_back(std::move(ds));
    info.cameras.push_back(camera);
  }
}

// A compressed session needs its filter plugin to read; say so now rather than fail on the
// first frame with HDF5's "can't open directory or file" from deep inside the plugin loader.
bool SessionReader::Impl::check_filters(hid_t dataset, const std::string& where) const {
  h5::PropertyList dcpl(h5::check(H5Dget_create_plist(dataset), "cannot read the creation properties of", where));
  const int n = h5::check(H5Pget_nfilters(dcpl.get()), "cannot read the filters of", where);
  for (int i = 0; i < n; ++i) {
    unsigned flags = 0;
    std::size_t n_values = 0;
    unsigned config = 0;
    const H5Z_filter_t filter = H5Pget_filter2(dcpl.get(), static_cast<unsigned>(i), &flags, &n_values, nullptr, 0,
                                               nullptr, &config);
    if (filter < 0) h5::fail("cannot read the filters of", where);
    require_filter(filter, fmt::format("reading session '{}'", path.string()));
  }
  return n > 0;
}

template <typename T>
std::vector<T> SessionReader::Impl::read_set_dataset(hid_t group, const char* name, hid_t mem_type,
                                                     std::vector<hsize_t> record_shape) {
  const std::string where = layout::sets_path(name);
  if (!h5::link_exists(group, name)) invalid(fmt::format("{} is missing", where));
  h5::Dataset dataset = h5::open_dataset(group, name, where);
  const std::vector<hsize_t> dims = h5::dims_of(dataset.get(), where);
  std::vector<hsize_t> expected{sets};
  expected.insert(expected.end(), record_shape.begin(), record_shape.end());
  if (dims.size() != expected.size() || !std::equal(dims.begin() + 1, dims.end(), expected.begin() + 1))
    invalid(fmt::format("{} has shape [{}] but should be [{}]", where, fmt::join(dims, ", "), fmt::join(expected, ", ")));
  if (dims[0] != sets && (recording_complete || dims[0] < sets))
    corrupt(fmt::format("{} holds {} sets but the camera frames hold {}", where, dims[0], sets));
  // Integers only: HDF5 would convert a float dt_ns (or frame_present) without a word.
  {
    h5::Datatype type(h5::check(H5Dget_type(dataset.get()), "cannot read the type of", where));
    if (H5Tget_class(type.get()) != H5T_INTEGER)
      invalid(fmt::format("{} holds {}; integers are expected", where,
                          H5Tget_class(type.get()) == H5T_FLOAT ? "floating-point numbers" : "non-integers"));
    // The sets that count, not the extent: an interrupted live recording may have grown a
    // dataset for a set it never wrote.
    std::optional<std::uint64_t> stored_bytes = H5Tget_size(type.get());
    for (hsize_t d : expected) stored_bytes = stored_bytes ? checked_product(*stored_bytes, d) : std::nullopt;
    require_stored(dataset.get(), stored_bytes, where);
  }
  std::optional<std::uint64_t> count = 1;
  for (hsize_t d : dims) count = count ? checked_product(*count, d) : std::nullopt;
  require_memory(count ? checked_product(*count, sizeof(T)) : std::nullopt, where);
  const auto stored = static_cast<std::size_t>(*count);
  std::vector<T> values(stored);
  if (stored > 0) h5::read_all(dataset.get(), mem_type, values.data(), where);
  std::size_t n = 1;
  for (hsize_t d : expected) n *= d;
  values.resize(n);  // a live recording may hold the start of the next set
  return values;
}

void SessionReader::Impl::read_sets() {
  if (!h5::link_exists(file.get(), layout::kSets)) invalid("the group /sets is missing");
  h5::Group group = h5::open_group(file.get(), layout::kSets, "/sets");
  const hsize_t n_cams = cameras.size();
  if (!recording_complete) {
    // trigger_index is written last for each set, so it says how many sets are complete.
    for (const char* name : {layout::kTriggerIndex, layout::kTriggerTimestamp, layout::kDt, layout::kFrameTimestamp,
                             layout::kFramePresent})
      if (h5::link_exists(group.get(), name)) {
        h5::Dataset d = h5::open_dataset(group.get(), name, layout::sets_path(name));
        const std::vector<hsize_t> dims = h5::dims_of(d.get(), layout::sets_path(name));
        if (dims.empty()) invalid(fmt::format("{} is a scalar; it should have one record per set", layout::sets_path(name)));
        sets = std::min<std::uint64_t>(sets, dims[0]);
      }
  }
  trigger_index = read_set_dataset<std::uint64_t>(group.get(), layout::kTriggerIndex, H5T_NATIVE_UINT64, {});
  trigger_timestamp = read_set_dataset<std::int64_t>(group.get(), layout::kTriggerTimestamp, H5T_NATIVE_INT64, {});
  dt = read_set_dataset<std::int64_t>(group.get(), layout::kDt, H5T_NATIVE_INT64, {});
  frame_timestamp = read_set_dataset<std::int64_t>(group.get(), layout::kFrameTimestamp, H5T_NATIVE_INT64, {n_cams, 2});
  frame_present = read_set_dataset<std::uint8_t>(group.get(), layout::kFramePresent, H5T_NATIVE_UINT8, {n_cams, 2});

  const std::size_t per_set = 2 * cameras.size();
  for (std::uint64_t s = 0; s < sets; ++s) {
    const auto first = frame_present.begin() + static_cast<std::ptrdiff_t>(s * per_set);
    for (std::size_t k = 0; k < per_set; ++k)
      if (first[static_cast<std::ptrdiff_t>(k)] > 2)
        corrupt(fmt::format("/sets/frame_present of set {}, camera {}, frame {} is {}; it must be 0 (missing), 1 "
                            "(present) or 2 (present, from a free-running camera)",
                            s, info.cameras[k / 2].id, k % 2 == 0 ? 'A' : 'B', first[static_cast<std::ptrdiff_t>(k)]));
    const auto lost = std::count(first, first + static_cast<std::ptrdiff_t>(per_set), std::uint8_t{0});
    // 2: a free-running camera's frame, present but not of this event: the set is not complete.
    const auto unsynchronised = std::count(first, first + static_cast<std::ptrdiff_t>(per_set), std::uint8_t{2});
    missing += static_cast<int>(lost);
    incomplete += lost + unsynchronised > 0 ? 1 : 0;
  }
  check_frame_storage();
}

// A present frame of an unfiltered camera is one allocated chunk of exactly a frame: the file
// must store at least that many bytes, or the flags (or the extent) were damaged.
void SessionReader::Impl::check_frame_storage() {
  const std::size_t n = cameras.size();
  for (std::size_t c = 0; c < n; ++c) {
    std::uint64_t present = 0;
    for (std::uint64_t s = 0; s < sets; ++s)
      present += (frame_present[(s * n + c) * 2] != 0 ? 1 : 0) + (frame_present[(s * n + c) * 2 + 1] != 0 ? 1 : 0);
    const SessionCamera& camera = info.cameras[c];
    const std::uint64_t frame_bytes = static_cast<std::uint64_t>(camera.width) * camera.height *
                                      bytes_per_sample(cameras[c].sample_type);
    if (has_filters(cameras[c].frames.get(), cameras[c].where)) continue;
    const hsize_t stored = H5Dget_storage_size(cameras[c].frames.get());
    if (stored / frame_bytes < present)
      corrupt(fmt::format("camera {}: {} frames are marked present but {} stores {}", camera.id, present,
                          cameras[c].where, stored / frame_bytes));
  }
}

void SessionReader::Impl::check_index(std::uint64_t set_index) const {
  if (set_index >= sets)
    throw bad_input(sets == 0 ? fmt::format("set {} does not exist: session '{}' holds no sets", set_index,
                                            path.string())
                              : fmt::format("set {} does not exist: session '{}' holds sets 0 to {}", set_index,
                                            path.string(), sets - 1));
}

h5::Group SessionReader::Impl::truth_sets_group() const {
  if (!truth) throw bad_input(fmt::format("session '{}' holds no truth (only simulated sessions do)", path.string()));
  h5::Group t = h5::open_group(file.get(), layout::kTruth, "/truth");
  if (!h5::link_exists(t.get(), layout::kSets)) return {};
  return h5::open_group(t.get(), layout::kSets, "/truth/sets");
}

SessionReader::SessionReader(const fs::path& path) {
  h5::silence_errors();
  // Everything this reader will ask libhdf5 to parse is parsed first in a child process, where a
  // library crash or endless loop on a damaged file ends only the child (isolated_probe.h).
  require_safe_to_read(
      [&] {
        const Impl probe(path);
        probe.touch_lazily_read_objects();
      },
      "session file", path);
  impl_ = std::make_unique<Impl>(path);
}

SessionReader::~SessionReader() = default;

const SessionInfo& SessionReader::info() const { return impl_->info; }
const fs::path& SessionReader::path() const { return impl_->path; }
int SessionReader::format_version() const { return impl_->format_version; }
std::uint64_t SessionReader::set_count() const { return impl_->sets; }
int SessionReader::missing_frames() const { return impl_->missing; }
int SessionReader::incomplete_sets() const { return impl_->incomplete; }
bool SessionReader::has_truth() const { return impl_->truth; }
bool SessionReader::recording_complete() const { return impl_->recording_complete; }

SetRecord SessionReader::set_record(std::uint64_t set_index) const {
  const Impl& m = *impl_;
  m.check_index(set_index);
  SetRecord r;
  r.trigger_index = m.trigger_index[set_index];
  r.trigger_timestamp_ns = m.trigger_timestamp[set_index];
  r.dt_ns = m.dt[set_index];
  const std::size_t n = m.cameras.size();
  r.frame_timestamp_ns.resize(n);
  r.frame_present.resize(n);
  r.frame_synchronised.resize(n);
  for (std::size_t c = 0; c < n; ++c)
    for (std::size_t e = 0; e < 2; ++e) {
      const std::size_t k = (set_index * n + c) * 2 + e;
      r.frame_timestamp_ns[c][e] = m.frame_timestamp[k];
      r.frame_present[c][e] = m.frame_present[k] != 0;
      r.frame_synchronised[c][e] = m.frame_present[k] != 2;
    }
  return r;
}

FrameSet SessionReader::read_set(std::uint64_t set_index) const {
  h5::silence_errors();
  const Impl& m = *impl_;
  const SetRecord record = set_record(set_index);
  FrameSet set;
  set.set_index = set_index;
  set.trigger_index = record.trigger_index;
  set.trigger_timestamp_ns = record.trigger_timestamp_ns;
  set.dt_ns = record.dt_ns;
  set.cameras.resize(m.cameras.size());
  for (std::size_t c = 0; c < m.cameras.size(); ++c) {
    const CameraDataset& ds = m.cameras[c];
    const SessionCamera& camera = m.info.cameras[c];
    CameraFrames& frames = set.cameras[c];
    frames.camera_id = camera.id;
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      const auto k = static_cast<std::size_t>(e);
      Frame& frame = frames[e];
      frame.timestamp_ns = record.frame_timestamp_ns[c][k];
      frame.synchronised = record.frame_synchronised[c][k];
      if (!record.frame_present[c][k]) continue;  // lost when recorded: stays empty
      frame.image = uninitialised_image(camera.width, camera.height, ds.sample_type);
      const std::array<hsize_t, 4> offset{set_index, k, 0, 0};
      try {
        h5::read_block(ds.frames.get(), offset, ds.count, ds.mem_type, frame.image.data(), ds.where);
      } catch (const h5::Failure& failure) {
        m.corrupt(fmt::format("frame {} of camera {} in set {}: {}", e == Exposure::A ? 'A' : 'B', camera.id,
                              set_index, failure.what()));
      }
    }
  }
  return set;
}

SessionTruth SessionReader::Impl::read_truth() const {
  SessionTruth truth;
  try {
    h5::Group group = h5::open_group(file.get(), layout::kTruth, "/truth");
    truth.case_name = h5::read_string_attr(group.get(), layout::kAttrCase, "/truth");
    truth.flow_name = h5::read_string_attr(group.get(), layout::kAttrFlow, "/truth");
    truth.flow_parameters = h5::read_string_attr(group.get(), layout::kAttrFlowParameters, "/truth");
    truth.seed = h5::read_uint64_attr(group.get(), layout::kAttrSeed, "/truth");
    truth.ppp = h5::read_double_attr(group.get(), layout::kAttrPpp, "/truth");
    if (!h5::link_exists(group.get(), layout::kCameras)) return truth;
    h5::Group cameras = h5::open_group(group.get(), layout::kCameras, "/truth/cameras");
    const std::vector<std::string> order =
        h5::read_string_list_attr(cameras.get(), layout::kAttrOrder, "/truth/cameras");
    check_order(order, "/truth/cameras 'order'");
    for (const std::string& id : order) {
      const std::string where = "/truth/cameras/" + id;
      h5::Group g = h5::open_group(cameras.get(), id.c_str(), where);
      TruthCamera c;
      c.id = id;
      c.model = h5::read_string_attr(g.get(), layout::kAttrModel, where);
      const auto K = h5::read_doubles_attr(g.get(), layout::kAttrK, 9, where);
      const auto R = h5::read_doubles_attr(g.get(), layout::kAttrR, 9, where);
      const auto t = h5::read_doubles_attr(g.get(), layout::kAttrT, 3, where);
      std::copy(K.begin(), K.end(), c.K.begin());
      std::copy(R.begin(), R.end(), c.R.begin());
      c.t = {t[0], t[1], t[2]};
      c.width = read_bounded_int(g.get(), layout::kAttrWidth, 1, layout::kMaxImageSide, where);
      c.height = read_bounded_int(g.get(), layout::kAttrHeight, 1, layout::kMaxImageSide, where);
      truth.cameras.push_back(std::move(c));
    }
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
  return truth;
}

TruthSet SessionReader::Impl::read_truth_set(std::uint64_t set_index, bool headers_only) const {
  TruthSet truth;
  try {
    h5::Group sets_group = truth_sets_group();
    const std::string where = layout::truth_set_path(set_index);
    h5::Group g = h5::open_group(sets_group.get(), layout::truth_set_name(set_index).c_str(), where);
    for (const auto& [name, particles] : {std::pair{layout::kParticlesA, &truth.particles_a},
                                          std::pair{layout::kParticlesB, &truth.particles_b}}) {
      const std::string dataset_path = where + "/" + name;
      h5::Dataset ds = h5::open_dataset(g.get(), name, dataset_path);
      const std::vector<hsize_t> dims = h5::dims_of(ds.get(), dataset_path);
      if (dims.size() != 2 || dims[1] != 3)
        invalid(fmt::format("{} should have shape [N, 3] (x, y, z in mm)", dataset_path));
      const auto bytes = checked_product(dims[0], sizeof(Vec3d));
      require_stored(ds.get(), bytes, dataset_path);
      require_memory(bytes, dataset_path);
      if (headers_only) continue;
      particles->resize(dims[0]);
      if (dims[0] > 0) h5::read_all(ds.get(), H5T_NATIVE_DOUBLE, particles->data(), dataset_path);
    }
  } catch (const h5::Failure& failure) {
    corrupt(failure.what());
  }
  return truth;
}

void SessionReader::Impl::touch_lazily_read_objects() const {
  read_quicklook();
  if (!truth) return;
  read_truth();
  h5::Group sets_group = truth_sets_group();
  if (!sets_group.valid()) return;
  H5G_info_t group_info{};
  h5::check(H5Gget_info(sets_group.get(), &group_info), "cannot list", "/truth/sets");
  for (std::uint64_t k = 0; k < sets; ++k)
    if (h5::link_exists(sets_group.get(), layout::truth_set_name(k).c_str())) read_truth_set(k, true);
}

SessionTruth SessionReader::truth() const {
  h5::silence_errors();
  const Impl& m = *impl_;
  if (!m.truth) throw bad_input(fmt::format("session '{}' holds no truth (only simulated sessions do)", m.path.string()));
  return m.read_truth();
}

bool SessionReader::has_truth_set(std::uint64_t set_index) const {
  h5::silence_errors();
  if (!impl_->truth) return false;
  try {
    h5::Group sets = impl_->truth_sets_group();
    return sets.valid() && h5::link_exists(sets.get(), layout::truth_set_name(set_index).c_str());
  } catch (const h5::Failure& failure) {
    impl_->corrupt(failure.what());
  }
}

std::uint64_t SessionReader::truth_set_count() const {
  h5::silence_errors();
  if (!impl_->truth) return 0;
  try {
    h5::Group sets = impl_->truth_sets_group();
    if (!sets.valid()) return 0;
    H5G_info_t group_info{};
    h5::check(H5Gget_info(sets.get(), &group_info), "cannot list", "/truth/sets");
    return group_info.nlinks;
  } catch (const h5::Failure& failure) {
    impl_->corrupt(failure.what());
  }
}

TruthSet SessionReader::truth_set(std::uint64_t set_index) const {
  h5::silence_errors();
  const Impl& m = *impl_;
  if (!has_truth_set(set_index))
    throw bad_input(fmt::format("session '{}' holds no truth for set {}", m.path.string(), set_index));
  return m.read_truth_set(set_index, false);
}

std::vector<QuickLookRecord> SessionReader::quicklook() const {
  h5::silence_errors();
  return impl_->read_quicklook();
}

std::vector<QuickLookRecord> SessionReader::Impl::read_quicklook() const {
  const Impl& m = *this;
  std::vector<QuickLookRecord> records;
  if (!h5::link_exists(m.file.get(), layout::kQuickLook)) return records;
  try {
    h5::Group group = h5::open_group(m.file.get(), layout::kQuickLook, "/quicklook");
    struct Table {
      h5::Dataset dataset;
      std::vector<hsize_t> dims;
      std::vector<std::string> columns;
    };
    auto open = [&](const char* name, std::size_t rank, bool with_columns) {
      const std::string where = layout::quicklook_path(name);
      if (!h5::link_exists(group.get(), name)) m.invalid(fmt::format("{} is missing", where));
      Table t{h5::open_dataset(group.get(), name, where), {}, {}};
      t.dims = h5::dims_of(t.dataset.get(), where);
      if (t.dims.size() != rank) m.invalid(fmt::format("{} has {} dimensions, not {}", where, t.dims.size(), rank));
      // Declared extents come from the file: bound them before anything is allocated.
      std::optional<std::uint64_t> bytes = std::uint64_t{4};
      for (hsize_t d : t.dims) bytes = bytes ? checked_product(*bytes, d) : std::nullopt;
      if (bytes && rank == 1) bytes = checked_product(*bytes, 2);  // the set index is 8 bytes wide
      m.require_memory(bytes, where);
      m.require_stored(t.dataset.get(), bytes, where);
      if (with_columns) {
        t.columns = h5::read_string_list_attr(t.dataset.get(), layout::kAttrColumns, where);
        if (t.columns.size() != t.dims.back())
          m.invalid(fmt::format("{} has {} columns but {} column names", where, t.dims.back(), t.columns.size()));
      }
      return t;
    };
    Table index = open(layout::kQuickLookSetIndex, 1, false);
    Table sets = open(layout::kQuickLookSets, 2, true);
    Table cameras = open(layout::kQuickLookCameras, 3, true);
    if (cameras.dims[1] != m.cameras.size())
      m.invalid(fmt::format("/quicklook/cameras holds {} cameras but the session has {}", cameras.dims[1],
                            m.cameras.size()));
    // The set index is written last: it says how many rows are whole (a live file may hold the
    // start of the next one in the tables).
    const hsize_t rows = std::min({index.dims[0], sets.dims[0], cameras.dims[0]});
    if (rows == 0) return records;
    std::vector<std::uint64_t> set_index(index.dims[0]);
    h5::read_all(index.dataset.get(), H5T_NATIVE_UINT64, set_index.data(), "/quicklook/set_index");
    std::vector<float> set_values(sets.dims[0] * sets.dims[1]);
    h5::read_all(sets.dataset.get(), H5T_NATIVE_FLOAT, set_values.data(), "/quicklook/sets");
    std::vector<float> camera_values(cameras.dims[0] * cameras.dims[1] * cameras.dims[2]);
    h5::read_all(cameras.dataset.get(), H5T_NATIVE_FLOAT, camera_values.data(), "/quicklook/cameras");

    const std::vector<int> set_positions = detail::column_positions(quicklook_set_columns(), sets.columns);
    const std::vector<int> camera_positions = detail::column_positions(quicklook_camera_columns(), cameras.columns);
    const std::size_t set_width = sets.dims[1], camera_width = cameras.dims[2], n_cams = cameras.dims[1];
    std::map<std::uint64_t, QuickLookRecord> by_set;
    for (std::size_t r = 0; r < rows; ++r) {
      QuickLookRecord row;
      row.set_index = set_index[r];
      detail::read_set_row(std::span(set_values).subspan(r * set_width, set_width), set_positions, row);
      row.cameras.resize(n_cams);
      for (std::size_t c = 0; c < n_cams; ++c)
        detail::read_camera_row(std::span(camera_values).subspan((r * n_cams + c) * camera_width, camera_width),
                                camera_positions, row.cameras[c]);
      const auto [it, first] = by_set.try_emplace(row.set_index, row);
      if (!first) detail::merge(it->second, row);
    }
    for (auto& [index, record] : by_set) records.push_back(std::move(record));
  } catch (const h5::Failure& failure) {
    m.corrupt(failure.what());
  }
  return records;
}

}  // namespace tomorig::storage
