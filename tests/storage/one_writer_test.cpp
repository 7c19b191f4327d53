// One writer per output name (issue 14, defect 2): a second writer on a name that is being
// written is refused before it changes anything, and the "<name>.partial" a killed recording
// left behind is never replaced, not even with --overwrite. In-process writers first, then the
// tomorig binary as a user runs it (a recording killed with SIGKILL, then run again).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "../apps/child_process.h"
#include "cli_runner.h"
#include "storage_test_support.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::expect_error;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;

const std::vector<SessionCamera> kCameras{test_camera("cam0", 32, 24, PixelFormat::Mono16)};

SessionInfo test_info() {
  SessionInfo info;
  info.cameras = kCameras;
  return info;
}

SessionWriterOptions live(bool overwrite = false) {
  SessionWriterOptions o;
  o.live = true;
  o.overwrite = overwrite;
  return o;
}

// Size and modification time: what "nothing was touched" means for a file.
struct FileState {
  std::uintmax_t size = 0;
  std::int64_t mtime_ns = 0;
  bool operator==(const FileState&) const = default;
};
FileState state_of(const fs::path& p) {
  struct stat s {};
  if (stat(p.c_str(), &s) != 0) return {};
  return {static_cast<std::uintmax_t>(s.st_size), s.st_mtim.tv_sec * 1'000'000'000LL + s.st_mtim.tv_nsec};
}

TEST(OneWriter, SecondSessionWriterOnTheSameNameIsRefusedAndTheFirstFinishes) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  for (const bool live_recording : {false, true}) {
    SCOPED_TRACE(live_recording ? "live" : "one go");
    std::error_code ec;
    fs::remove(path, ec);
    SessionWriterOptions first_options = live_recording ? live() : SessionWriterOptions{};
    SessionWriter first(path, test_info(), first_options);
    first.append(test_set(kCameras, 0));
    const FileState before = state_of(first.partial_path());
    for (const bool overwrite : {false, true})
      expect_error([&] { SessionWriter second(path, test_info(), live(overwrite)); }, ErrorKind::bad_input,
                   {"s.h5", "is being written by another process", "nothing was changed"});
    EXPECT_EQ(state_of(first.partial_path()), before);
    first.append(test_set(kCameras, 1));
    first.finish();
    EXPECT_FALSE(fs::exists(fs::path(path).concat(".lock"))) << "a finished writer leaves no lock file";
    const SessionReader reader(path);
    EXPECT_EQ(reader.set_count(), 2u);
  }
}

TEST(OneWriter, LeftOverPartialIsNeverReplacedEvenWithOverwrite) {
  TempDir dir;
  const fs::path path = dir / "a.h5";
  {
    SessionWriter abandoned(path, test_info(), live());
    for (std::uint64_t k = 0; k < 3; ++k) abandoned.append(test_set(kCameras, k));
  }  // no finish(): as after a crash, "a.h5.partial" keeps the sets
  const fs::path partial = dir / "a.h5.partial";
  const FileState before = state_of(partial);
  ASSERT_GT(before.size, 0u);
  for (const bool overwrite : {false, true})
    expect_error([&] { SessionWriter again(path, test_info(), live(overwrite)); }, ErrorKind::bad_input,
                 {"a.h5.partial", "did not finish", "not even with --overwrite", "tomorig inspect", "mv ",
                  "a-recovered.h5", "h5clear -s", "rm "});
  EXPECT_EQ(state_of(partial), before);
  EXPECT_FALSE(fs::exists(path));
  const SessionReader kept(partial);
  EXPECT_EQ(kept.set_count(), 3u);
}

TEST(OneWriter, LockFileLeftByADeadWriterIsTakenOver) {
  TempDir dir;
  const fs::path path = dir / "s.h5";
  dir.write("s.h5.lock", "12345\n");  // what SIGKILL leaves: a lock file nobody holds
  testing::write_test_session(path, kCameras, 1);
  EXPECT_EQ(SessionReader(path).set_count(), 1u);
  EXPECT_FALSE(fs::exists(dir / "s.h5.lock"));
}

TEST(OneWriter, SecondResultsWriterOnTheSameFileIsRefused) {
  TempDir dir;
  const fs::path path = dir / "r.h5";
  const ResultsInfo info{.session_path = "s.h5", .session_identity = "id", .voxel_size_mm = 0.02};
  ResultsWriter first(path, info);
  first.write();
  const FileState before = state_of(path);
  for (const bool overwrite : {false, true})
    expect_error([&] { ResultsWriter second(path, info, {.overwrite = overwrite}); }, ErrorKind::bad_input,
                 {"results file", "r.h5", "is being written by another process"});
  EXPECT_EQ(state_of(path), before);
  first.close();
}

// The tomorig binary, as issue 14 ran it.
class OneWriterCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig::testing::tomorig_built()) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
  }
  static tomorig::testing::CliResult run(const std::string& args) { return tomorig::testing::run_tomorig(args); }
  static std::string quote(const fs::path& p) { return tomorig::testing::shell_quoted(p.string()); }
};

TEST_F(OneWriterCli, SecondRunOnTheSameNameRefusesAndAKilledRunsPartialSurvivesARerun) {
  TempDir dir;
  const fs::path out = dir / "a.h5";
  const fs::path partial = dir / "a.h5.partial";
  tomorig::testing::TomorigProcess first({"run", "--sets", "200", "-o", out.string()});
  // The live writer makes sets durable every 10 sets (or every second); set 10 is flushed before
  // its status line is printed, so a SIGKILL from here on must leave at least 10 readable sets.
  ASSERT_TRUE(first.wait_for_line("recording: set 10/")) << first.err();

  // A second writer while the first records: refused, the first's file untouched.
  const FileState recording = state_of(partial);
  tomorig::testing::CliResult second = run("run --sets 3 --pace max --status none -o " + quote(out));
  EXPECT_EQ(second.exit_code, 2) << second.err;
  EXPECT_NE(second.err.find("is being written by another process"), std::string::npos) << second.err;
  EXPECT_GE(state_of(partial).size, recording.size);  // still growing, never truncated

  first.send_signal(SIGKILL);
  ASSERT_EQ(first.wait(), -1);
  ASSERT_TRUE(fs::exists(partial));
  ASSERT_FALSE(fs::exists(out));
  const FileState killed = state_of(partial);
  const std::uint64_t sets = SessionReader(partial).set_count();
  ASSERT_GE(sets, 10u);

  // Run again on the same name, with and without --overwrite: the crashed run's sets survive.
  for (const std::string overwrite : {"", " --overwrite"}) {
    tomorig::testing::CliResult rerun = run("run --sets 3 --pace max --status none" + overwrite + " -o " + quote(out));
    EXPECT_EQ(rerun.exit_code, 2) << rerun.err;
    EXPECT_NE(rerun.err.find("did not finish"), std::string::npos) << rerun.err;
    EXPECT_NE(rerun.err.find("h5clear -s"), std::string::npos) << rerun.err;
    EXPECT_EQ(state_of(partial), killed);
    EXPECT_FALSE(fs::exists(out));
  }
  EXPECT_EQ(SessionReader(partial).set_count(), sets);
  const tomorig::testing::CliResult inspect = run("inspect " + quote(partial));
  EXPECT_EQ(inspect.exit_code, 0) << inspect.err;
}

TEST_F(OneWriterCli, ProcessRefusesAResultsFileAnotherWriterHolds) {
  TempDir dir;
  const fs::path session = dir / "s.h5";
  const fs::path results = dir / "r.h5";
  tomorig::testing::CliResult sim = run("simulate --sets 1 --ppp 0.02 -o " + quote(session));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  {
    // Another `process` on the same results file, as far as the lock is concerned.
    ResultsWriter holder(results, {.session_identity = "other", .voxel_size_mm = 0.02});
    tomorig::testing::CliResult r = run("process --session " + quote(session) + " --calib truth --grid 96,96,160,0.0195 --window 32,32,32 -o " +
                                         quote(results));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("is being written by another process"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(results)) << "the refused run wrote the results file";
  }
}

}  // namespace
}  // namespace tomorig::storage
