// A full disk under a live recording: the recorder must stop, say so, and leave a file that
// opens and holds every set written before. Uses a real tmpfs of a few MB (root only).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "disk_full_tmpfs.h"
#include "storage_test_support.h"

namespace tomorig::storage::testing {
namespace {

using tomorig::testing::SmallTmpfs;

// One 512 x 512 Mono16 camera: 1 MiB of pixels per set (frames A and B).
std::vector<SessionCamera> one_camera() { return {test_camera("cam0", 512, 512, PixelFormat::Mono16)}; }

SessionInfo info_for(const std::vector<SessionCamera>& cameras) {
  SessionInfo info;
  info.cameras = cameras;
  info.rig_config_toml = "name = \"disk full test\"\n";
  return info;
}

void expect_same_pixels(const FrameSet& expected, const FrameSet& actual) {
  ASSERT_EQ(expected.cameras.size(), actual.cameras.size());
  for (std::size_t c = 0; c < expected.cameras.size(); ++c)
    for (const Exposure e : {Exposure::A, Exposure::B}) {
      ASSERT_TRUE(expected.cameras[c][e].image.same_pixels(actual.cameras[c][e].image))
          << "set " << expected.set_index << " camera " << c;
    }
}

TEST(SessionDiskFull, ReserveStopsTheRecordingCleanlyWithEverySetKept) {
  SmallTmpfs disk(12);
  if (!disk.available()) GTEST_SKIP() << disk.why();
  const auto cameras = one_camera();
  const auto path = disk / "full.h5";
  SessionWriterOptions options;
  options.live = true;
  options.disk_reserve_bytes = 2'000'000;
  SessionWriter writer(path, info_for(cameras), options);
  std::uint64_t appended = 0;
  std::string message;
  for (std::uint64_t k = 0; k < 100; ++k) {
    try {
      writer.append(test_set(cameras, k));
      ++appended;
    } catch (const DiskFullError& e) {
      message = e.what();
      break;
    }
  }
  ASSERT_FALSE(message.empty()) << "12 MB never filled up after " << appended << " sets of 1 MiB";
  EXPECT_NE(message.find("full"), std::string::npos) << message;
  EXPECT_NE(message.find(path.string() + ".partial"), std::string::npos) << message;  // names the file
  EXPECT_GE(appended, 5u);  // 12 MB minus the 2 MB reserve holds several sets
  writer.finish();

  const SessionReader reader(path);
  EXPECT_TRUE(reader.recording_complete());
  ASSERT_EQ(reader.set_count(), appended);
  for (std::uint64_t k = 0; k < appended; ++k) expect_same_pixels(test_set(cameras, k), reader.read_set(k));
}

TEST(SessionDiskFull, HardWriteFailureKeepsAReadablePartialFileWithTheFlushedSets) {
  // No reserve: HDF5 itself hits ENOSPC. The writer refuses further use and keeps
  // "<name>.partial", which must open and hold every set up to the last flush (every set here).
  SmallTmpfs disk(6);
  if (!disk.available()) GTEST_SKIP() << disk.why();
  const auto cameras = one_camera();
  const auto path = disk / "hard.h5";
  SessionWriterOptions options;
  options.live = true;
  options.flush.every_sets = 1;
  std::uint64_t appended = 0;
  std::string message;
  {
    SessionWriter writer(path, info_for(cameras), options);
    for (std::uint64_t k = 0; k < 100; ++k) {
      try {
        writer.append(test_set(cameras, k));
        ++appended;
      } catch (const Error& e) {
        message = e.what();
        break;
      }
    }
    ASSERT_FALSE(message.empty()) << "6 MB never filled up";
    EXPECT_THROW(writer.append(test_set(cameras, appended)), Error);  // refuses further use
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  ASSERT_TRUE(std::filesystem::exists(path.string() + ".partial"));
  const SessionReader reader(path.string() + ".partial");
  EXPECT_FALSE(reader.recording_complete());
  // Every set whose append() returned was flushed; the failing one may or may not have made it.
  ASSERT_GE(reader.set_count(), appended);
  ASSERT_GE(appended, 2u);
  for (std::uint64_t k = 0; k < reader.set_count(); ++k) expect_same_pixels(test_set(cameras, k), reader.read_set(k));
}

}  // namespace
}  // namespace tomorig::storage::testing
