// What the session reader refuses before it trusts a file (issue 14, defects 5 to 8): camera
// ids that are not valid ids, a camera listed twice, an index attribute that disagrees with the
// camera order, flags that are not 0 or 1, floats where integers belong, and declared sizes that
// would make it allocate gigabytes; and what the writer refuses to record. Each file is made by
// the real writer, then changed with the HDF5 C API the way a damaged or hand-made file would be.
// Also: session files of format version 1 (variable-length strings) are still read.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "storage_test_support.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/session_summary.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using namespace std::string_literals;
using testing::expect_error;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;
using testing::write_test_session;

const std::vector<SessionCamera> kFour{
    test_camera("cam0", 16, 12, PixelFormat::Mono16), test_camera("cam1", 16, 12, PixelFormat::Mono16),
    test_camera("cam2", 16, 12, PixelFormat::Mono16), test_camera("cam3", 16, 12, PixelFormat::Mono16)};

// A finished session opened read-write with the C API.
class Edit {
 public:
  explicit Edit(const fs::path& path) : file_(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)) {
    if (file_ < 0) throw std::runtime_error("cannot open " + path.string());
  }
  ~Edit() { H5Fclose(file_); }

  // Replaces attribute `name` of `object` with one of `type` holding `count` values at `data`.
  void replace_attr(const char* object, const char* name, hid_t type, const void* data, hsize_t count = 0) {
    const hid_t obj = H5Oopen(file_, object, H5P_DEFAULT);
    if (H5Aexists(obj, name) > 0) H5Adelete(obj, name);
    const hid_t space = count == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &count, nullptr);
    const hid_t attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(H5Awrite(attr, type, data), 0);
    H5Aclose(attr);
    H5Sclose(space);
    H5Oclose(obj);
  }
  void replace_order(const std::vector<std::string>& ids) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    std::vector<const char*> pointers;
    for (const auto& id : ids) pointers.push_back(id.c_str());
    replace_attr("/cameras", "order", type, pointers.data(), ids.size());
    H5Tclose(type);
  }
  void set_int_attr(const char* object, const char* name, std::int64_t value) {
    replace_attr(object, name, H5T_NATIVE_INT64, &value);
  }
  // Writes one uint8 element of a dataset at `offset` (rank 3).
  void write_u8(const char* dataset, std::array<hsize_t, 3> offset, std::uint8_t value) {
    const hid_t ds = H5Dopen2(file_, dataset, H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    const hsize_t one[3] = {1, 1, 1};
    H5Sselect_hyperslab(space, H5S_SELECT_SET, offset.data(), nullptr, one, nullptr);
    const hid_t memory = H5Screate_simple(3, one, nullptr);
    EXPECT_GE(H5Dwrite(ds, H5T_NATIVE_UINT8, memory, space, H5P_DEFAULT, &value), 0);
    H5Sclose(memory);
    H5Sclose(space);
    H5Dclose(ds);
  }
  // Replaces a one-dimensional /sets dataset by a float64 one holding `values`.
  void replace_with_doubles(const char* dataset, const std::vector<double>& values) {
    H5Ldelete(file_, dataset, H5P_DEFAULT);
    const hsize_t n = values.size();
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t ds = H5Dcreate2(file_, dataset, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    EXPECT_GE(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
    H5Dclose(ds);
    H5Sclose(space);
  }
  // Grows the first dimension of a chunked dataset without writing: HDF5 stores only the extent.
  void declare_first_dim(const char* dataset, hsize_t n) {
    const hid_t ds = H5Dopen2(file_, dataset, H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    hsize_t dims[4] = {};
    const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
    ASSERT_GT(rank, 0);
    dims[0] = n;
    ASSERT_GE(H5Dset_extent(ds, dims), 0);
    H5Sclose(space);
    H5Dclose(ds);
  }
  // Replaces a /sets dataset by a deflate-compressed one of `rows` records (of `record` elements
  // of `type`, zeros), as another tool might write it; compressed data says nothing about its size.
  void replace_with_compressed(const char* dataset, hid_t type, std::vector<hsize_t> record, hsize_t rows) {
    H5Ldelete(file_, dataset, H5P_DEFAULT);
    std::vector<hsize_t> dims{rows}, max{H5S_UNLIMITED}, chunk{512};
    for (hsize_t r : record) dims.push_back(r), max.push_back(r), chunk.push_back(r);
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), max.data());
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data());
    H5Pset_deflate(dcpl, 6);
    const hid_t ds = H5Dcreate2(file_, dataset, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    EXPECT_GE(ds, 0) << dataset;
    H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(space);
  }
  hid_t id() const { return file_; }

 private:
  hid_t file_;
};

fs::path four_camera_session(const TempDir& dir, int sets = 2) {
  const fs::path path = dir / "s.h5";
  write_test_session(path, kFour, sets);
  return path;
}

TEST(SessionValidation, OneCameraListedFourTimesIsRefused) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  Edit(path).replace_order({"cam0", "cam0", "cam0", "cam0"});
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input, {path.string(), "lists camera 'cam0' twice"});
}

TEST(SessionValidation, IndexAttributeMustMatchTheCameraOrder) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  {
    Edit edit(path);
    edit.set_int_attr("/cameras/cam0", "index", 1);
    edit.set_int_attr("/cameras/cam1", "index", 0);
  }
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "camera cam0 has index 1 but is listed at position 0"});
}

TEST(SessionValidation, FramePresentMustBeZeroOrOne) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  Edit(path).write_u8("/sets/frame_present", {1, 2, 0}, 7);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "frame_present of set 1, camera cam2, frame A is 7"});
}

TEST(SessionValidation, FloatsWhereIntegersBelongAreRefused) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  Edit(path).replace_with_doubles("/sets/dt_ns", {100000.5, 100001.0});
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "/sets/dt_ns holds floating-point numbers; integers are expected"});

  const fs::path version = dir / "version.h5";
  write_test_session(version, kFour, 1);
  const double one = 1.0;
  Edit(version).replace_attr("/", "format_version", H5T_NATIVE_DOUBLE, &one);
  expect_error([&] { SessionReader r(version); }, ErrorKind::bad_input,
               {version.string(), "format_version", "floating-point"});
}

TEST(SessionValidation, InvalidCameraIdsInAFileAreRefusedAndNeverEchoedRaw) {
  TempDir dir;
  for (const std::string& id : {"\xff\xfe"s, "cam\x1b[2J"s, "."s}) {
    const fs::path path = four_camera_session(dir);
    {
      Edit edit(path);
      // The group really exists under that name, so only the id rule can refuse it.
      if (id != ".") {
        const std::string moved = "/cameras/" + id;
        ASSERT_GE(H5Lmove(edit.id(), "/cameras/cam1", edit.id(), moved.c_str(), H5P_DEFAULT, H5P_DEFAULT), 0);
      }
      edit.replace_order({"cam0", id, "cam2", "cam3"});
    }
    try {
      SessionReader r(path);
      ADD_FAILURE() << "accepted camera id " << ::testing::PrintToString(id);
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      const std::string message = e.what();
      EXPECT_NE(message.find("is not allowed"), std::string::npos) << message;
      EXPECT_EQ(message.find('\x1b'), std::string::npos) << "raw escape sequence in the message";
      EXPECT_EQ(message.find('\xff'), std::string::npos) << "raw non-UTF-8 byte in the message";
    }
    fs::remove(path);
  }
}

TEST(SessionValidation, WriterRefusesIdsThatAreNotValidIds) {
  TempDir dir;
  for (const std::string& id : {"\xff"s, "a\0b"s, "a/b"s, ".."s, "cam\x1b[31m"s}) {
    SessionInfo info;
    info.cameras = {test_camera(id, 8, 8, PixelFormat::Mono8)};
    expect_error([&] { SessionWriter w(dir / "w.h5", info); }, ErrorKind::bad_input, {"is not allowed"});
    EXPECT_FALSE(fs::exists(dir / "w.h5.partial"));
  }
  SessionInfo many;
  for (int c = 0; c < 300; ++c) many.cameras.push_back(test_camera(std::to_string(c), 1, 1, PixelFormat::Mono8));
  expect_error([&] { SessionWriter w(dir / "many.h5", many); }, ErrorKind::bad_input, {"300 cameras", "at most 256"});
}

// Defect 6: a small file declaring a billion sets made every command allocate gigabytes and
// die with a bare std::bad_alloc.
TEST(SessionValidation, DeclaredSetCountBeyondWhatTheFileStoresIsRefused) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  {
    Edit edit(path);
    const hsize_t billion = 1'000'000'000;
    for (const char* c : {"/cameras/cam0/frames", "/cameras/cam1/frames", "/cameras/cam2/frames", "/cameras/cam3/frames",
                          "/sets/trigger_index", "/sets/trigger_timestamp_ns", "/sets/dt_ns",
                          "/sets/frame_timestamp_ns", "/sets/frame_present"})
      edit.declare_first_dim(c, billion);
  }
  ASSERT_LT(fs::file_size(path), 1u << 20);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "corrupt", "declares", "bytes of data but the file stores"});
}

// The same with compressed records (another tool's file): the stored size proves nothing, so the
// memory the records would take is bounded by the file's size (16 times, at least 64 MiB).
TEST(SessionValidation, DeclaredSetCountOfCompressedRecordsIsBoundedByTheFileSize) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  {
    Edit edit(path);
    const hsize_t billion = 1'000'000'000;
    for (const char* c : {"/cameras/cam0/frames", "/cameras/cam1/frames", "/cameras/cam2/frames", "/cameras/cam3/frames"})
      edit.declare_first_dim(c, billion);
    edit.replace_with_compressed("/sets/trigger_index", H5T_STD_U64LE, {}, billion);
    edit.replace_with_compressed("/sets/trigger_timestamp_ns", H5T_STD_I64LE, {}, billion);
    edit.replace_with_compressed("/sets/dt_ns", H5T_STD_I64LE, {}, billion);
    edit.replace_with_compressed("/sets/frame_timestamp_ns", H5T_STD_I64LE, {4, 2}, billion);
    edit.replace_with_compressed("/sets/frame_present", H5T_STD_U8LE, {4, 2}, billion);
  }
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "/sets/trigger_index would take 8000000000 bytes of memory", "declared size is damaged"});
}

// Defect 6: declared 65536 x 65536 frames drove `replay` to 8 GB; a frame is one HDF5 chunk
// (< 4 GiB), so such a camera cannot be in a session.
TEST(SessionValidation, FramesLargerThanAChunkCanBeAreRefused) {
  TempDir dir;
  const fs::path path = dir / "huge.h5";
  write_test_session(path, {test_camera("cam0", 16, 16, PixelFormat::Mono16)}, 1);
  {
    Edit edit(path);
    H5Ldelete(edit.id(), "/cameras/cam0/frames", H5P_DEFAULT);
    const hsize_t dims[4] = {1, 2, 65536, 65536}, chunk[4] = {1, 1, 256, 256};
    const hid_t space = H5Screate_simple(4, dims, nullptr);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 4, chunk);
    H5Dclose(H5Dcreate2(edit.id(), "/cameras/cam0/frames", H5T_STD_U16LE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT));
    H5Pclose(dcpl);
    H5Sclose(space);
    edit.set_int_attr("/cameras/cam0", "width", 65536);
    edit.set_int_attr("/cameras/cam0", "height", 65536);
  }
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input, {path.string(), "65536 x 65536", "at most"});

  // A width past any camera is refused before it is narrowed to int (2^32 + 16 would read as 16).
  write_test_session(dir / "wide.h5", {test_camera("cam0", 16, 16, PixelFormat::Mono16)}, 1);
  Edit(dir / "wide.h5").set_int_attr("/cameras/cam0", "width", (std::int64_t{1} << 32) + 16);
  expect_error([&] { SessionReader r(dir / "wide.h5"); }, ErrorKind::bad_input, {"width", "4294967312", "1 to 65536"});
}

// A string dataset declaring 2^40 strings of 1 MiB (an exabyte, stored as nothing: chunked and
// never written): before the strings were sized against a limit, the reader asked for the whole
// buffer and died of a bare std::bad_alloc (ASan: allocation-size-too-big), and an extent and
// size whose product wraps around 2^64 would have had HDF5 write past a small buffer.
TEST(SessionValidation, StringsLargerThanAFileCanHoldAreRefused) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  {
    Edit edit(path);
    H5Ldelete(edit.id(), "/config", H5P_DEFAULT);
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, std::size_t{1} << 20);
    const hsize_t dims[1] = {hsize_t{1} << 40}, max[1] = {H5S_UNLIMITED}, chunk[1] = {1};
    const hid_t space = H5Screate_simple(1, dims, max);
    const hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(dcpl, 1, chunk);
    const hid_t ds = H5Dcreate2(edit.id(), "/config", type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    ASSERT_GE(ds, 0);
    H5Dclose(ds);
    H5Pclose(dcpl);
    H5Sclose(space);
    H5Tclose(type);
  }
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "/config declares 1099511627776 strings of 1048576 bytes", "damaged"});
}

TEST(SessionValidation, FramesMarkedPresentMustBeStored) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  {
    SessionInfo info;
    info.cameras = kFour;
    SessionWriter writer(path, info);
    FrameSet set = test_set(kFour, 0);
    set.cameras[1].b.image = Image();  // lost when recorded: no chunk is written
    writer.append(set);
    writer.finish();
  }
  Edit(path).write_u8("/sets/frame_present", {0, 1, 1}, 1);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "camera cam1: 2 frames are marked present but", "stores 1"});
}

// Defect 8: span of the trigger timestamps INT64_MIN .. INT64_MAX overflowed a signed subtraction.
TEST(SessionValidation, SummarySpansTheWholeTimestampRange) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  {
    SessionInfo info;
    info.cameras = {kFour[0]};
    SessionWriter writer(path, info);
    for (const std::int64_t t : {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()}) {
      FrameSet set = test_set(info.cameras, 0);
      set.trigger_timestamp_ns = t;
      writer.append(set);
    }
    writer.finish();
  }
  const SessionSummary s = summarize(SessionReader(path));
  EXPECT_EQ(s.first_trigger_ns, std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(s.last_trigger_ns, std::numeric_limits<std::int64_t>::max());
  EXPECT_NEAR(s.time_span_s, 18446744073.709551615, 1e-3);
}

// New files keep every string fixed-length (format version 2): no global heap to damage.
TEST(SessionValidation, NewFilesStoreFixedLengthStrings) {
  TempDir dir;
  const fs::path path = four_camera_session(dir);
  const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(file, 0);
  for (const auto& [object, name] : {std::pair{"/", "format"}, std::pair{"/", "software_version"},
                                     std::pair{"/", "created_utc"}, std::pair{"/", "compression"},
                                     std::pair{"/cameras", "order"}, std::pair{"/cameras/cam0", "pixel_format"}}) {
    const hid_t attr = H5Aopen_by_name(file, object, name, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t type = H5Aget_type(attr);
    EXPECT_EQ(H5Tget_class(type), H5T_STRING) << object << " " << name;
    EXPECT_EQ(H5Tis_variable_str(type), 0) << object << " " << name;
    H5Tclose(type);
    H5Aclose(attr);
  }
  const hid_t config = H5Dopen2(file, "/config", H5P_DEFAULT);
  const hid_t type = H5Dget_type(config);
  EXPECT_EQ(H5Tis_variable_str(type), 0);
  H5Tclose(type);
  H5Dclose(config);
  H5Fclose(file);
  const SessionReader reader(path);
  EXPECT_EQ(reader.format_version(), 2);
  EXPECT_EQ(reader.info().cameras[3].id, "cam3");
  EXPECT_EQ(reader.info().rig_config_toml, "name = \"test rig\"\n");
}

// Version 1 files, made by tomorig before the change (`simulate` with bitshuffle-lz4 and a live
// `run`, 32 x 24 cameras), are still read, variable-length strings and all.
TEST(SessionValidation, Version1FilesAreStillRead) {
  const fs::path data = fs::path(TOMORIG_SOURCE_DIR) / "tests/storage/data";
  const SessionReader simulated(data / "session-v1-simulate.h5");
  EXPECT_EQ(simulated.format_version(), 1);
  EXPECT_EQ(simulated.info().compression, Compression::bitshuffle_lz4);
  ASSERT_EQ(simulated.info().cameras.size(), 4u);
  EXPECT_EQ(simulated.info().cameras[2].id, "cam2");
  EXPECT_EQ(simulated.info().cameras[2].width, 32);
  EXPECT_EQ(simulated.set_count(), 2u);
  EXPECT_NE(simulated.info().rig_config_toml.find("tpiv-thesis"), std::string::npos);
  ASSERT_TRUE(simulated.has_truth());
  EXPECT_EQ(simulated.truth().case_name, "tpiv-thesis");
  EXPECT_EQ(simulated.truth_set(1).particles_a.size(), simulated.truth_set(1).particles_b.size());
  EXPECT_TRUE(simulated.read_set(1).cameras[3].b.present());

  const SessionReader live(data / "session-v1-run.h5");
  EXPECT_EQ(live.format_version(), 1);
  EXPECT_TRUE(live.recording_complete());
  EXPECT_EQ(live.set_count(), 2u);
  EXPECT_EQ(live.missing_frames(), 0);
}

}  // namespace
}  // namespace tomorig::storage
