// Live recording (HDF5 SWMR): a file that can be read while it grows, that keeps its sets when
// the writer is abandoned, and in which every set before the last flush survives a SIGKILL at
// any moment. The writer runs in a forked child so that it can really be killed; parent and
// child synchronise through pipes, never through sleeps.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>

#include "storage_test_support.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;

const std::vector<SessionCamera> kCameras{test_camera("cam0", 64, 48, PixelFormat::Mono16),
                                          test_camera("cam1", 40, 30, PixelFormat::Mono8)};

SessionWriterOptions live_options(Compression compression, std::uint64_t flush_every_sets) {
  SessionWriterOptions o;
  o.compression = compression;
  o.live = true;
  o.flush.every_sets = flush_every_sets;
  o.flush.every_seconds = 3600.0;  // flush by count only, so the test knows when
  return o;
}

SessionInfo test_info() {
  SessionInfo info;
  info.cameras = kCameras;
  info.rig_config_toml = "name = \"live test\"\n";
  return info;
}

// Every set the reader reports is bit-identical to what was appended, records included.
void expect_sets_intact(const SessionReader& reader) {
  for (std::uint64_t k = 0; k < reader.set_count(); ++k) {
    const FrameSet want = test_set(kCameras, k);
    const FrameSet got = reader.read_set(k);
    EXPECT_EQ(got.trigger_index, want.trigger_index) << "set " << k;
    EXPECT_EQ(got.dt_ns, want.dt_ns) << "set " << k;
    ASSERT_EQ(got.cameras.size(), want.cameras.size());
    for (std::size_t c = 0; c < want.cameras.size(); ++c) {
      ASSERT_TRUE(got.cameras[c].a.present() && got.cameras[c].b.present()) << "set " << k;
      EXPECT_TRUE(got.cameras[c].a.image.same_pixels(want.cameras[c].a.image)) << "set " << k << " camera " << c;
      EXPECT_TRUE(got.cameras[c].b.image.same_pixels(want.cameras[c].b.image)) << "set " << k << " camera " << c;
      EXPECT_EQ(got.cameras[c].b.timestamp_ns, want.cameras[c].b.timestamp_ns);
    }
  }
}

// A pipe whose ends close with the object.
struct Pipe {
  int fd[2] = {-1, -1};
  Pipe() {
    if (pipe(fd) != 0) throw std::runtime_error("pipe failed");
  }
  ~Pipe() {
    for (int f : fd)
      if (f >= 0) close(f);
  }
};

// Child: writes sets until killed, reporting through `report` the number of sets that are
// flushed (the writer flushes inside append() every `every` sets).
[[noreturn]] void write_until_killed(const fs::path& path, Compression compression, std::uint64_t every,
                                     int report) {
  try {
    SessionWriter writer(path, test_info(), live_options(compression, every));
    for (std::uint64_t k = 0;; ++k) {
      writer.append(test_set(kCameras, k));
      const std::uint64_t done = writer.sets_written();
      if (done % every == 0 && write(report, &done, sizeof done) != sizeof done) _exit(3);
    }
  } catch (...) {
    _exit(2);
  }
}

class LiveRecordingKill : public ::testing::TestWithParam<Compression> {};

TEST_P(LiveRecordingKill, EveryFlushedSetSurvivesSigkill) {
  for (const std::uint64_t kill_after : {1u, 9u, 40u}) {
    TempDir dir;
    const fs::path path = dir / "live.h5";
    Pipe pipe;
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      close(pipe.fd[0]);
      write_until_killed(path, GetParam(), 3, pipe.fd[1]);
    }
    close(pipe.fd[1]);
    pipe.fd[1] = -1;
    std::uint64_t flushed = 0;
    while (flushed < kill_after) {
      ASSERT_EQ(read(pipe.fd[0], &flushed, sizeof flushed), static_cast<ssize_t>(sizeof flushed))
          << "the writer died before flushing " << kill_after << " sets";
    }
    // The child is busy writing the next sets now: kill it mid-write.
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));

    EXPECT_FALSE(fs::exists(path)) << "an unfinished recording must not take the final name";
    const fs::path partial = dir / "live.h5.partial";
    ASSERT_TRUE(fs::exists(partial));
    const SessionReader reader(partial);
    EXPECT_FALSE(reader.recording_complete());
    EXPECT_GE(reader.set_count(), flushed) << "killed after " << kill_after;
    EXPECT_EQ(reader.info().rig_config_toml, test_info().rig_config_toml);
    expect_sets_intact(reader);
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, LiveRecordingKill,
                         ::testing::Values(Compression::none, Compression::bitshuffle_lz4),
                         [](const auto& info) { return info.param == Compression::none ? "none" : "bitshuffle_lz4"; });

TEST(LiveRecording, ReadableWhileBeingWritten) {
  TempDir dir;
  const fs::path path = dir / "live.h5";
  Pipe progress, go_on;
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(progress.fd[0]);
    close(go_on.fd[1]);
    try {
      SessionWriter writer(path, test_info(), live_options(Compression::none, 1));
      for (std::uint64_t k = 0; k < 5; ++k) writer.append(test_set(kCameras, k));
      const std::uint64_t done = writer.sets_written();
      char c = 0;
      if (write(progress.fd[1], &done, sizeof done) != sizeof done || read(go_on.fd[0], &c, 1) != 1) _exit(3);
      for (std::uint64_t k = 5; k < 8; ++k) writer.append(test_set(kCameras, k));
      writer.finish();
    } catch (...) {
      _exit(2);
    }
    _exit(0);
  }
  close(progress.fd[1]);
  progress.fd[1] = -1;
  close(go_on.fd[0]);
  go_on.fd[0] = -1;
  std::uint64_t written = 0;
  ASSERT_EQ(read(progress.fd[0], &written, sizeof written), static_cast<ssize_t>(sizeof written));
  {
    // The writer is alive and holds the file open: a reader sees the five flushed sets.
    const SessionReader live(dir / "live.h5.partial");
    EXPECT_FALSE(live.recording_complete());
    EXPECT_EQ(live.set_count(), written);
    expect_sets_intact(live);
  }
  const char c = 'g';
  ASSERT_EQ(write(go_on.fd[1], &c, 1), 1);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0);
  const SessionReader done(path);
  EXPECT_TRUE(done.recording_complete());
  EXPECT_EQ(done.set_count(), 8u);
  expect_sets_intact(done);
  EXPECT_FALSE(fs::exists(dir / "live.h5.partial"));
}

TEST(LiveRecording, AbandonedWriterKeepsItsSetsAndFinishedOneIsComplete) {
  TempDir dir;
  {
    SessionWriter writer(dir / "a.h5", test_info(), live_options(Compression::none, 100));
    for (std::uint64_t k = 0; k < 4; ++k) writer.append(test_set(kCameras, k));
    // No finish(): a full disk or an exception in the caller ends the recording here.
  }
  EXPECT_FALSE(fs::exists(dir / "a.h5"));
  const SessionReader kept(dir / "a.h5.partial");
  EXPECT_FALSE(kept.recording_complete());
  EXPECT_EQ(kept.set_count(), 4u);  // closing flushes, whatever the policy
  expect_sets_intact(kept);

  // Finished live recordings are ordinary sessions, with the truth written at the end.
  {
    SessionWriter writer(dir / "b.h5", test_info(), live_options(Compression::bitshuffle_lz4, 2));
    SessionTruth truth;
    truth.case_name = "tpiv-thesis";
    truth.seed = 7;
    writer.write_truth(truth);
    for (std::uint64_t k = 0; k < 3; ++k) {
      writer.append(test_set(kCameras, k));
      writer.write_truth_set(k, {{{1.0 * k, 2.0, 3.0}}, {{1.5 * k, 2.0, 3.0}}});
    }
    writer.finish();
  }
  const SessionReader done(dir / "b.h5");
  EXPECT_TRUE(done.recording_complete());
  EXPECT_EQ(done.set_count(), 3u);
  expect_sets_intact(done);
  ASSERT_TRUE(done.has_truth());
  EXPECT_EQ(done.truth().seed, 7u);
  EXPECT_EQ(done.truth_set(2).particles_b.at(0).x, 3.0);
}

}  // namespace
}  // namespace tomorig::storage
