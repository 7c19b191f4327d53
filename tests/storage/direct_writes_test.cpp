// Frame chunks of session files bypass the page cache (storage/src/direct_write_driver.h): the
// file must read back bit-identical, while it is recorded (SWMR) and after, whether the frame's
// memory is page-aligned or not and whether its size is a whole number of pages or not.
#include <fcntl.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <memory>

#include "direct_write_driver.h"
#include "storage_test_support.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;

// 512^2 Mono16: 512 KiB, whole pages. 1000 x 700 Mono16 and 600 x 500 Mono8: above the direct
// threshold, with a last partial page. 64 x 48: below it (always through the page cache).
const std::vector<SessionCamera> kCameras{
    test_camera("whole", 512, 512, PixelFormat::Mono16), test_camera("tail16", 1000, 700, PixelFormat::Mono16),
    test_camera("tail8", 600, 500, PixelFormat::Mono8), test_camera("small", 64, 48, PixelFormat::Mono16)};

// The pixels of `image` copied into page-aligned memory, so the driver writes them without its
// bounce buffers.
Image page_aligned_copy(const Image& image) {
  const std::size_t bytes = (image.size_bytes() + kDirectAlignment - 1) / kDirectAlignment * kDirectAlignment;
  std::shared_ptr<void> memory(std::aligned_alloc(kDirectAlignment, bytes), std::free);
  std::memcpy(memory.get(), image.data(), image.size_bytes());
  return Image::view(memory.get(), image.width(), image.height(), image.type(), 0, memory);
}

// What test_set(kCameras, k) holds; every other set's frames in page-aligned memory.
FrameSet set_to_write(std::uint64_t k) {
  FrameSet set = test_set(kCameras, k);
  if (k % 2 == 1)
    for (CameraFrames& frames : set.cameras) {
      frames.a.image = page_aligned_copy(frames.a.image);
      frames.b.image = page_aligned_copy(frames.b.image);
    }
  return set;
}

void expect_sets_intact(const SessionReader& reader, std::uint64_t sets) {
  ASSERT_EQ(reader.set_count(), sets);
  for (std::uint64_t k = 0; k < sets; ++k) {
    const FrameSet want = test_set(kCameras, k);
    const FrameSet got = reader.read_set(k);
    ASSERT_EQ(got.cameras.size(), want.cameras.size());
    for (std::size_t c = 0; c < want.cameras.size(); ++c) {
      EXPECT_TRUE(got.cameras[c].a.image.same_pixels(want.cameras[c].a.image)) << "set " << k << " camera " << c;
      EXPECT_TRUE(got.cameras[c].b.image.same_pixels(want.cameras[c].b.image)) << "set " << k << " camera " << c;
    }
  }
}

SessionInfo session_info() {
  SessionInfo info;
  info.cameras = kCameras;
  info.rig_config_toml = "name = \"direct writes\"\n";
  return info;
}

bool folder_takes_direct_io(const fs::path& folder) {
  const fs::path probe = folder / "direct-io-probe";
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_DIRECT, 0644);
  if (fd >= 0) ::close(fd);
  std::error_code ec;
  fs::remove(probe, ec);
  return fd >= 0;
}

TEST(DirectWrites, LiveSessionReadsBackBitIdenticalWhileRecordedAndAfter) {
  TempDir dir;
  const fs::path out = dir / "live.h5";
  SessionWriterOptions options;
  options.live = true;
  options.flush.every_sets = 1;
  const std::size_t direct_before = direct_bytes_written();
  {
    SessionWriter writer(out, session_info(), options);
    for (std::uint64_t k = 0; k < 3; ++k) writer.append(set_to_write(k));
    // A reader with HDF5's default driver, during the recording.
    expect_sets_intact(SessionReader(writer.partial_path()), 3);
    writer.append(set_to_write(3));
    writer.finish();
  }
  expect_sets_intact(SessionReader(out), 4);

  if (folder_takes_direct_io(dir.path())) {
    // Whole pages of every frame above the threshold went direct: 4 sets x 2 frames.
    const std::size_t pages_per_set = 2 * (512 * 512 * 2 + 1000 * 700 * 2 / kDirectAlignment * kDirectAlignment +
                                           600 * 500 / kDirectAlignment * kDirectAlignment);
    EXPECT_GE(direct_bytes_written() - direct_before, 4 * pages_per_set);
  }
}

TEST(DirectWrites, FinishedSessionWithCompressionReadsBackBitIdentical) {
  TempDir dir;
  const fs::path out = dir / "compressed.h5";
  SessionWriterOptions options;
  options.compression = Compression::bitshuffle_lz4;
  {
    SessionWriter writer(out, session_info(), options);
    for (std::uint64_t k = 0; k < 3; ++k) writer.append(set_to_write(k));
    writer.finish();
  }
  expect_sets_intact(SessionReader(out), 3);
}

}  // namespace
}  // namespace tomorig::storage
