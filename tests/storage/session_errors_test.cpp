// Bad input gives tomorig::Error of kind bad_input with a message that names the file and
// the problem, and a failed write leaves nothing behind.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "storage_test_support.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;
using testing::write_test_session;

const std::vector<SessionCamera> kCameras{test_camera("cam0", 32, 24, PixelFormat::Mono16),
                                          test_camera("cam1", 32, 24, PixelFormat::Mono16)};

// Opens a finished session with the HDF5 C API to damage it the way a bug or a crash could.
class RawFile {
 public:
  explicit RawFile(const fs::path& path) : id_(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT)) {
    if (id_ < 0) throw std::runtime_error("cannot open " + path.string());
  }
  ~RawFile() { H5Fclose(id_); }
  hid_t id() const { return id_; }

  void set_int_attr(const char* object, const char* name, std::int64_t value) {
    const hid_t obj = H5Oopen(id_, object, H5P_DEFAULT);
    const hid_t attr = H5Aopen(obj, name, H5P_DEFAULT);
    ASSERT_GE(attr, 0);
    ASSERT_GE(H5Awrite(attr, H5T_NATIVE_INT64, &value), 0);
    H5Aclose(attr);
    H5Oclose(obj);
  }
  void shrink_first_dim(const char* dataset, hsize_t n) {
    const hid_t ds = H5Dopen2(id_, dataset, H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    hsize_t dims[4] = {};
    const int rank = H5Sget_simple_extent_dims(space, dims, nullptr);
    ASSERT_GT(rank, 0);
    dims[0] = n;
    ASSERT_GE(H5Dset_extent(ds, dims), 0);
    H5Sclose(space);
    H5Dclose(ds);
  }

 private:
  hid_t id_;
};

TEST(SessionReaderErrors, MissingFile) {
  TempDir dir;
  const fs::path path = dir / "nope.h5";
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input, {path.string(), "does not exist"});
}

TEST(SessionReaderErrors, FolderInsteadOfFile) {
  TempDir dir;
  expect_error([&] { SessionReader r(dir.path()); }, ErrorKind::bad_input, {dir.path().string(), "folder"});
}

TEST(SessionReaderErrors, NotAnHdf5File) {
  TempDir dir;
  const fs::path path = dir / "notes.h5";
  std::ofstream(path) << "these are not the frames you are looking for\n";
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input, {path.string(), "not an HDF5 file"});
}

TEST(SessionReaderErrors, Hdf5FileThatIsNotASession) {
  TempDir dir;
  const fs::path path = dir / "other.h5";
  H5Fclose(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "not a valid tomorig session", "'format'"});
}

TEST(SessionReaderErrors, UnsupportedFormatVersion) {
  TempDir dir;
  const fs::path path = dir / "future.h5";
  write_test_session(path, kCameras, 1);
  RawFile(path).set_int_attr("/", "format_version", 3);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "format version 3", "reads versions 1 to 2"});
}

TEST(SessionReaderErrors, FramesDisagreeWithCameraSize) {
  TempDir dir;
  const fs::path path = dir / "sizes.h5";
  write_test_session(path,
                     {test_camera("cam0", 16, 16, PixelFormat::Mono8), test_camera("cam1", 16, 16, PixelFormat::Mono8),
                      test_camera("cam2", 256, 256, PixelFormat::Mono8)},
                     1);
  {
    RawFile raw(path);
    raw.set_int_attr("/cameras/cam2", "width", 512);
    raw.set_int_attr("/cameras/cam2", "height", 512);
  }
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "camera cam2: frames are 256 x 256 but the session says 512 x 512"});
}

TEST(SessionReaderErrors, TruncatedSetsDataset) {
  TempDir dir;
  const fs::path path = dir / "short.h5";
  write_test_session(path, kCameras, 3);
  RawFile(path).shrink_first_dim("/sets/dt_ns", 2);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "corrupt or truncated", "/sets/dt_ns holds 2 sets but the camera frames hold 3"});
}

TEST(SessionReaderErrors, CamerasWithDifferentSetCounts) {
  TempDir dir;
  const fs::path path = dir / "ragged.h5";
  write_test_session(path, kCameras, 3);
  RawFile(path).shrink_first_dim("/cameras/cam1/frames", 1);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input,
               {path.string(), "corrupt or truncated", "camera cam1 holds 1 sets but camera cam0 holds 3"});
}

TEST(SessionReaderErrors, FileTruncatedOnDisk) {
  TempDir dir;
  const fs::path path = dir / "cut.h5";
  write_test_session(path, kCameras, 4);
  fs::resize_file(path, fs::file_size(path) / 2);
  expect_error([&] { SessionReader r(path); }, ErrorKind::bad_input, {path.string(), "corrupt or truncated"});
}

TEST(SessionReaderErrors, SetIndexOutOfRange) {
  TempDir dir;
  write_test_session(dir / "s.h5", kCameras, 2);
  SessionReader reader(dir / "s.h5");
  expect_error([&] { reader.read_set(2); }, ErrorKind::bad_input, {"set 2 does not exist", "0 to 1"});
  expect_error([&] { reader.truth(); }, ErrorKind::bad_input, {"no truth"});
  expect_error([&] { reader.truth_set(0); }, ErrorKind::bad_input, {"no truth for set 0"});
}

TEST(SessionWriterErrors, MissingFolder) {
  TempDir dir;
  const fs::path path = dir / "no" / "such" / "folder" / "s.h5";
  SessionInfo info;
  info.cameras = kCameras;
  expect_error([&] { SessionWriter w(path, info); }, ErrorKind::bad_input, {path.string(), "does not exist"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(SessionWriterErrors, FolderIsAFile) {
  TempDir dir;
  std::ofstream(dir / "plain") << "x";
  const fs::path path = dir / "plain" / "s.h5";
  SessionInfo info;
  info.cameras = kCameras;
  expect_error([&] { SessionWriter w(path, info); }, ErrorKind::bad_input, {path.string(), "not a folder"});
}

TEST(SessionWriterErrors, UnwritableFolderLeavesNothingBehind) {
  if (geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  TempDir dir;
  const fs::path locked = dir / "locked";
  fs::create_directory(locked);
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_exec);
  const fs::path path = locked / "s.h5";
  SessionInfo info;
  info.cameras = kCameras;
  expect_error([&] { SessionWriter w(path, info); }, ErrorKind::bad_input, {path.string(), "writable"});
  fs::permissions(locked, fs::perms::owner_all);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(fs::path(path).concat(".partial")));
}

TEST(SessionWriterErrors, ExistingFileWithoutOverwrite) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  write_test_session(path, kCameras, 1);
  const auto size = fs::file_size(path);
  SessionInfo info;
  info.cameras = kCameras;
  expect_error([&] { SessionWriter w(path, info); }, ErrorKind::bad_input, {path.string(), "already exists"});
  EXPECT_EQ(fs::file_size(path), size);  // untouched
  EXPECT_FALSE(fs::exists(fs::path(path).concat(".partial")));
}

TEST(SessionWriterErrors, WrongImageSizeInAppend) {
  TempDir dir;
  SessionInfo info;
  info.cameras = kCameras;
  SessionWriter writer(dir / "s.h5", info);
  FrameSet set = test_set(kCameras, 0);
  set.cameras[1].b.image = Image::allocate(31, 24, SampleType::u16);
  expect_error([&] { writer.append(set); }, ErrorKind::bad_input, {"camera cam1", "frame B", "31 x 24", "32 x 24"});
  EXPECT_EQ(writer.sets_written(), 0u);  // nothing written for the rejected set
  writer.append(test_set(kCameras, 0));  // and the writer is still usable
  writer.finish();
  EXPECT_EQ(SessionReader(dir / "s.h5").set_count(), 1u);
}

TEST(SessionWriterErrors, WrongSampleTypeInAppend) {
  TempDir dir;
  SessionInfo info;
  info.cameras = kCameras;
  SessionWriter writer(dir / "s.h5", info);
  FrameSet set = test_set(kCameras, 0);
  set.cameras[0].a.image = Image::allocate(32, 24, SampleType::u8);
  expect_error([&] { writer.append(set); }, ErrorKind::bad_input, {"camera cam0", "uint8", "uint16"});
}

TEST(SessionWriterErrors, UnknownCameraInAppend) {
  TempDir dir;
  SessionInfo info;
  info.cameras = kCameras;
  SessionWriter writer(dir / "s.h5", info);
  FrameSet set = test_set(kCameras, 0);
  set.cameras[1].camera_id = "cam7";
  expect_error([&] { writer.append(set); }, ErrorKind::bad_input, {"cam7", "cam0, cam1"});
}

TEST(SessionWriterErrors, BadCameraDefinitions) {
  TempDir dir;
  SessionInfo info;
  expect_error([&] { SessionWriter w(dir / "a.h5", info); }, ErrorKind::bad_input, {"at least one camera"});
  info.cameras = {test_camera("cam0", 8, 8, PixelFormat::Mono8), test_camera("cam0", 8, 8, PixelFormat::Mono8)};
  expect_error([&] { SessionWriter w(dir / "b.h5", info); }, ErrorKind::bad_input, {"cam0", "twice"});
  info.cameras = {test_camera("a/b", 8, 8, PixelFormat::Mono8)};
  expect_error([&] { SessionWriter w(dir / "c.h5", info); }, ErrorKind::bad_input, {"a/b", "'/'"});
  info.cameras = {test_camera("cam0", 0, 8, PixelFormat::Mono8)};
  expect_error([&] { SessionWriter w(dir / "d.h5", info); }, ErrorKind::bad_input, {"cam0", "0 x 8"});
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(SessionWriterErrors, FinishTwiceAndAppendAfterFinish) {
  TempDir dir;
  SessionInfo info;
  info.cameras = kCameras;
  SessionWriter writer(dir / "s.h5", info);
  writer.finish();
  expect_error([&] { writer.append(test_set(kCameras, 0)); }, ErrorKind::runtime, {"already finished"});
  expect_error([&] { writer.finish(); }, ErrorKind::runtime, {"already finished"});
  EXPECT_TRUE(fs::exists(dir / "s.h5"));
}

}  // namespace
}  // namespace tomorig::storage
