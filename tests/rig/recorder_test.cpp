// rig::Recorder: the one lossless recorder of `run` and `record`, tested without threads or
// sockets: FrameSets built from arrays, then the session file read back.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include "temp_dir.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/recorder.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

// A set of `cameras` cameras with width x 8 u16 frames whose pixels hold `value`.
FrameSet make_set(int cameras, int width, std::uint16_t value, std::uint64_t trigger = 0) {
  FrameSet set;
  set.trigger_index = trigger;
  set.dt_ns = 1000;
  for (int c = 0; c < cameras; ++c) {
    CameraFrames frames;
    frames.camera_id = "cam" + std::to_string(c);
    for (Frame* f : {&frames.a, &frames.b}) {
      f->image = Image::allocate(width, 8, SampleType::u16);
      for (int y = 0; y < f->image.height(); ++y)
        for (int x = 0; x < width; ++x) f->image.row<std::uint16_t>(y)[x] = value;
    }
    set.cameras.push_back(std::move(frames));
  }
  return set;
}

TEST(Recorder, LearnsTheCamerasFromTheFirstSetAndRefusesSetsThatDiffer) {
  TempDir tmp;
  rig::Recorder recorder({.out = tmp / "s.h5"});
  EXPECT_FALSE(recorder.started());  // no camera list yet: no file yet
  EXPECT_EQ(recorder.add(make_set(2, 16, 100, 7)), rig::Recorder::Outcome::written);
  std::string why;
  EXPECT_EQ(recorder.add(make_set(2, 20, 200), nullptr, &why), rig::Recorder::Outcome::refused);
  EXPECT_NE(why.find("cam0"), std::string::npos) << why;
  EXPECT_EQ(recorder.add(make_set(3, 16, 300), nullptr, &why), rig::Recorder::Outcome::refused);
  EXPECT_EQ(recorder.add(make_set(2, 16, 400, 9)), rig::Recorder::Outcome::written);

  const rig::RecorderReport& report = recorder.finish();
  EXPECT_TRUE(report.finished);
  EXPECT_EQ(report.written, 2u);
  EXPECT_EQ(report.refused, 2u);
  EXPECT_EQ(report.bytes, 2u * 2 * 2 * 16 * 8 * 2);
  EXPECT_NE(report.brief().find("recorded 2 sets"), std::string::npos) << report.brief();

  const storage::SessionReader session(tmp / "s.h5");
  ASSERT_EQ(session.set_count(), 2u);
  ASSERT_EQ(session.info().cameras.size(), 2u);
  EXPECT_EQ(session.info().cameras[1].width, 16);
  EXPECT_EQ(session.set_record(1).trigger_index, 9u);
  const FrameSet second = session.read_set(1);  // the refused sets never reached the file
  EXPECT_EQ(second.cameras[0].a.image.row<std::uint16_t>(0)[0], 400);
}

TEST(Recorder, KnownCamerasCreateTheSessionAtOnceWithConfigAndTruth) {
  TempDir tmp;
  storage::SessionTruth truth;
  truth.case_name = "unit";
  rig::Recorder recorder({.out = tmp / "sub" / "s.h5",
                          .cameras = {{.id = "cam0", .width = 16, .height = 8, .pixel_format = PixelFormat::Mono16}},
                          .rig_config_toml = "name = \"unit\"\n",
                          .truth = truth});
  EXPECT_TRUE(recorder.started());
  EXPECT_TRUE(std::filesystem::exists(tmp / "sub" / "s.h5.partial"));
  storage::TruthSet particles;
  particles.particles_a.push_back({1.0, 2.0, 3.0});
  EXPECT_EQ(recorder.add(make_set(1, 16, 5), &particles), rig::Recorder::Outcome::written);
  recorder.finish();

  const storage::SessionReader session(tmp / "sub" / "s.h5");
  EXPECT_EQ(session.info().rig_config_toml, "name = \"unit\"\n");
  ASSERT_TRUE(session.has_truth());
  EXPECT_EQ(session.truth().case_name, "unit");
  ASSERT_TRUE(session.has_truth_set(0));
  EXPECT_EQ(session.truth_set(0).particles_a.size(), 1u);
}

TEST(Recorder, AnExistingFileIsRefusedWithoutOverwrite) {
  TempDir tmp;
  const auto out = tmp.write("s.h5", "precious");
  try {
    rig::Recorder recorder({.out = out});
    FAIL() << "an existing file was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("--overwrite"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read_text_file(out), "precious");
}

TEST(Recorder, AFullDiskStopsCleanlyWithEverySetBeforeIt) {
  TempDir tmp;
  // No disk keeps a petabyte free: the first set already "fills" it.
  rig::Recorder recorder({.out = tmp / "s.h5",
                          .disk_reserve_mb = 1e9,
                          .cameras = {{.id = "cam0", .width = 16, .height = 8, .pixel_format = PixelFormat::Mono16}}});
  std::string why;
  EXPECT_EQ(recorder.add(make_set(1, 16, 1), nullptr, &why), rig::Recorder::Outcome::stopped);
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(recorder.add(make_set(1, 16, 1)), rig::Recorder::Outcome::stopped);  // and stays stopped
  const rig::RecorderReport& report = recorder.finish();
  EXPECT_EQ(report.written, 0u);
  EXPECT_FALSE(report.disk_full.empty());
  const storage::SessionReader session(tmp / "s.h5");  // complete and readable
  EXPECT_EQ(session.set_count(), 0u);
  EXPECT_TRUE(session.recording_complete());
}

TEST(Recorder, NothingToFinishWhenNoSetStartedTheSession) {
  TempDir tmp;
  rig::Recorder recorder({.out = tmp / "s.h5"});
  FrameSet empty;
  EXPECT_EQ(recorder.add(empty), rig::Recorder::Outcome::refused);
  EXPECT_THROW(recorder.finish(), Error);
  EXPECT_FALSE(std::filesystem::exists(tmp / "s.h5"));
}

TEST(Recorder, BadOptionsNameTheFlag) {
  TempDir tmp;
  try {
    rig::Recorder recorder({.out = tmp / "s.h5", .disk_reserve_mb = -1});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--disk-reserve-mb"), std::string::npos) << e.what();
  }
  EXPECT_THROW(rig::parse_compression_option("zip"), Error);
  EXPECT_EQ(rig::parse_compression_option("bitshuffle-lz4"), storage::Compression::bitshuffle_lz4);
}

}  // namespace
}  // namespace tomorig::testing
