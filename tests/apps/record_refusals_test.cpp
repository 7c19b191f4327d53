// `tomorig record` fed sets it cannot write (issue 14, item 4): a first set with a bad camera id,
// with 32 767 one-pixel cameras, with more cameras than a session holds, or past --max-set-mb.
// Each must be counted and skipped while record keeps running, and the good sets that follow
// must make a valid file holding exactly them. Before the fix, such a first set made record
// exit 2 (the writer's refusal escaped the count-and-continue path).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "child_process.h"
#include "cli_runner.h"
#include "scripted_sender.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

// `count` cameras c0, c1, ... of width x height Mono8, both frames present.
FrameSet set_of_cameras(std::uint64_t index, int count, int width, int height) {
  FrameSet set;
  set.set_index = index;
  set.trigger_index = 100 + index;
  set.cameras.resize(static_cast<std::size_t>(count));
  for (int c = 0; c < count; ++c) {
    CameraFrames& cam = set.cameras[static_cast<std::size_t>(c)];
    cam.camera_id = "c" + std::to_string(c);
    cam.a.image = Image::allocate(width, height, SampleType::u8);
    cam.b.image = Image::allocate(width, height, SampleType::u8);
  }
  return set;
}

FrameSet small_set_with_id(std::uint64_t index, const std::string& id) {
  FrameSet set = small_set(index);
  set.cameras[0].camera_id = id;
  return set;
}

// The file holds exactly small_set(0..n-1): cameras, indices and pixels.
void expect_small_sets(const std::filesystem::path& file, std::uint64_t n) {
  const storage::SessionReader session(file);
  ASSERT_EQ(session.set_count(), n);
  ASSERT_EQ(session.info().cameras.size(), 2u);
  EXPECT_EQ(session.info().cameras[0].id, "cam0");
  EXPECT_EQ(session.info().cameras[1].id, "cam1");
  for (std::uint64_t s = 0; s < n; ++s) {
    const FrameSet set = session.read_set(s);
    EXPECT_EQ(set.trigger_index, 100 + s);
    for (int c = 0; c < 2; ++c)
      for (const Frame* f : {&set.cameras[c].a, &set.cameras[c].b}) {
        ASSERT_FALSE(f->image.empty());
        EXPECT_EQ(f->image.at<std::uint16_t>(3, 5), small_pixel(s, c, 3, 5));
      }
  }
  EXPECT_TRUE(session.recording_complete());
}

class RecordRefusals : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  TempDir dir_;
  std::filesystem::path out_ = dir_ / "out.h5";
};

TEST_F(RecordRefusals, FirstSetsItCannotWriteAreCountedAndTheGoodSetsAfterThemRecorded) {
  ScriptedSender sender;
  // 10 kB: a small set (two 16 x 8 Mono16 cameras, both frames) is 1 kB.
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--sets", "3",
                         "--max-set-mb", "0.01"});
  ASSERT_TRUE(sender->send(small_set_with_id(90, "a/b")));     // rejected by the decoder
  ASSERT_TRUE(sender->send(small_set_with_id(91, "..")));      // rejected by the decoder
  ASSERT_TRUE(sender->send(set_of_cameras(92, 32767, 1, 1)));  // 2.9 MB message, 32 767 cameras
  ASSERT_TRUE(sender->send(set_of_cameras(93, 257, 1, 1)));    // one more than a session holds
  ASSERT_TRUE(sender->send(set_of_cameras(94, 2, 64, 48)));    // 12 kB: past --max-set-mb
  for (std::uint64_t s = 0; s < 3; ++s) ASSERT_TRUE(sender->send(small_set(s)));
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_NE(record.out().find("recorded 3 sets"), std::string::npos) << record.out();
  EXPECT_NE(record.out().find("3 refused sets, 2 rejected messages"), std::string::npos) << record.out();
  EXPECT_NE(record.err().find("32767 cameras; a session holds at most 256"), std::string::npos) << record.err();
  EXPECT_NE(record.err().find("--max-set-mb 0.01"), std::string::npos) << record.err();
  expect_small_sets(out_, 3);
}

TEST_F(RecordRefusals, AnnouncedSessionItCannotWriteIsSkippedAndTheNextSessionRecorded) {
  ScriptedSender sender;
  TomorigProcess record({"record", "--from", sender->endpoint(), "-o", out_.string(), "--idle-timeout", "60"});
  // A session start announcing 32 767 one-pixel cameras with their sizes: the file would be
  // opened at once, before any set.
  stream::SessionStart absurd;
  absurd.session_id = 5;
  for (int c = 0; c < 32767; ++c) absurd.info.cameras.push_back({"c" + std::to_string(c), 1, 1, PixelFormat::Mono8, 5.5});
  ASSERT_TRUE(sender->send(absurd));
  ASSERT_TRUE(sender->send(set_of_cameras(0, 32767, 1, 1)));  // its set: refused, counted
  ASSERT_TRUE(sender->send(small_start(6)));
  for (std::uint64_t s = 0; s < 2; ++s) ASSERT_TRUE(sender->send(small_set(s)));
  ASSERT_TRUE(sender->send(stream::SessionEnd{6, 2, stream::SessionOutcome::completed, ""}));
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_NE(record.err().find("session 0000000000000005 cannot be recorded"), std::string::npos) << record.err();
  EXPECT_NE(record.out().find("recorded 2 sets"), std::string::npos) << record.out();
  EXPECT_NE(record.out().find("1 refused sets"), std::string::npos) << record.out();
  expect_small_sets(out_, 2);
  EXPECT_EQ(storage::SessionReader(out_).info().software_version, "scripted-sender");
}

}  // namespace
}  // namespace tomorig::testing
