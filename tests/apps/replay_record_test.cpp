// `tomorig replay` and `tomorig record` end to end: real processes talking over loopback TCP.
// Replay binds a free port ("tcp://127.0.0.1:*") and prints it; record connects to it. The
// tests wait on printed lines and process exits only.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <string>

#include "child_process.h"
#include "cli_runner.h"
#include "session_compare.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

// The endpoint from replay's first stderr line "replay: sending on tcp://127.0.0.1:PORT, ...".
std::string endpoint_from(const std::string& line) {
  const std::string marker = "sending on ";
  const auto begin = line.find(marker);
  if (begin == std::string::npos) return {};
  const auto start = begin + marker.size();
  return line.substr(start, line.find(',', start) - start);
}

// One simulated 3-set session shared by the tests of a run, rendered on first use (ctest runs
// each test in its own process, so tests that do not need it do not pay for it).
class ReplayRecord : public ::testing::Test {
 protected:
  static void TearDownTestSuite() {
    delete folder_;
    folder_ = nullptr;
  }
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  static std::filesystem::path source() {
    if (folder_ == nullptr) {
      folder_ = new TempDir();
      const CliResult r = run_tomorig("simulate --sets 3 --ppp 0.01 -o " + shell_quoted((*folder_ / "src.h5").string()));
      EXPECT_EQ(r.exit_code, 0) << r.err;
    }
    return *folder_ / "src.h5";
  }

 private:
  static inline TempDir* folder_ = nullptr;
};

// Sets [0, count) of `copy` equal those of `source`: pixels, timestamps, trigger index, Δt.
void expect_same_sets(const std::filesystem::path& source, const std::filesystem::path& copy, std::uint64_t count) {
  const storage::SessionReader a(source);
  const storage::SessionReader b(copy);
  ASSERT_EQ(b.set_count(), count);
  ASSERT_EQ(a.info().cameras.size(), b.info().cameras.size());
  for (std::size_t c = 0; c < a.info().cameras.size(); ++c) {
    EXPECT_EQ(a.info().cameras[c].id, b.info().cameras[c].id);
    EXPECT_EQ(a.info().cameras[c].width, b.info().cameras[c].width);
    EXPECT_EQ(a.info().cameras[c].height, b.info().cameras[c].height);
  }
  for (std::uint64_t k = 0; k < count; ++k) {
    const FrameSet x = a.read_set(k);
    const FrameSet y = b.read_set(k);
    EXPECT_EQ(x.trigger_index, y.trigger_index) << "set " << k;
    EXPECT_EQ(x.trigger_timestamp_ns, y.trigger_timestamp_ns) << "set " << k;
    EXPECT_EQ(x.dt_ns, y.dt_ns) << "set " << k;
    ASSERT_EQ(x.cameras.size(), y.cameras.size());
    for (std::size_t c = 0; c < x.cameras.size(); ++c) {
      EXPECT_EQ(x.cameras[c].camera_id, y.cameras[c].camera_id);
      EXPECT_TRUE(x.cameras[c].a.image.same_pixels(y.cameras[c].a.image)) << "set " << k << " camera " << c << " A";
      EXPECT_TRUE(x.cameras[c].b.image.same_pixels(y.cameras[c].b.image)) << "set " << k << " camera " << c << " B";
      EXPECT_EQ(x.cameras[c].a.timestamp_ns, y.cameras[c].a.timestamp_ns);
      EXPECT_EQ(x.cameras[c].b.timestamp_ns, y.cameras[c].b.timestamp_ns);
    }
  }
}

TEST_F(ReplayRecord, RoundTripIsBitIdentical) {
  TempDir tmp;
  const auto src = source();
  const auto out = tmp / "out.h5";

  TomorigProcess replay({"replay", src.string(), "--to", "tcp://127.0.0.1:*", "--rate", "max"});
  const auto first_line = replay.wait_for_line("sending on");
  ASSERT_TRUE(first_line) << replay.err();
  const std::string endpoint = endpoint_from(*first_line);
  ASSERT_FALSE(endpoint.empty()) << *first_line;

  const CliResult record = run_tomorig("record --from " + endpoint + " -o " + shell_quoted(out.string()) +
                                       " --sets 3 --idle-timeout 60");
  ASSERT_EQ(record.exit_code, 0) << record.err;
  EXPECT_NE(record.out.find("recorded 3 sets"), std::string::npos) << record.out;
  ASSERT_EQ(replay.wait(), 0) << replay.err();
  EXPECT_NE(replay.out().find("replayed 3 sets"), std::string::npos) << replay.out();

  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  EXPECT_TRUE(storage::SessionReader(out).recording_complete());
  expect_same_sets(src, out, 3);
}

// Replay announces the session it reads, so the copy keeps /config, the attributes (creation
// time and software version included), pixel pitch and truth, and record stops by itself
// after the last set.
TEST_F(ReplayRecord, CopyKeepsConfigAttributesPitchAndTruthAndEndsByItself) {
  TempDir tmp;
  const auto src = source();
  const auto out = tmp / "copy.h5";
  TomorigProcess replay({"replay", src.string(), "--to", "tcp://127.0.0.1:*", "--rate", "max"});
  const auto first_line = replay.wait_for_line("sending on");
  ASSERT_TRUE(first_line) << replay.err();
  // Only the end of acquisition should end the recording (the idle timeout is a safety net).
  TomorigProcess record({"record", "--from", endpoint_from(*first_line), "-o", out.string(), "--idle-timeout", "120"});
  ASSERT_EQ(record.wait(), 0) << record.err();
  ASSERT_EQ(replay.wait(), 0) << replay.err();
  EXPECT_NE(record.out().find("the sender ended the session: completed"), std::string::npos) << record.out();
  expect_same_session_metadata(src, out, /*same_creation_time=*/true);
  expect_same_sets(src, out, 3);
}

TEST_F(ReplayRecord, SigintStopsRecordWithACompleteSession) {
  TempDir tmp;
  const auto src = source();
  const auto out = tmp / "out.h5";

  // A looping replay at 1 Hz never ends the session by itself, and its next set comes a second
  // after set 1: only the signal (or, if the test breaks, the idle timeout) ends the recording.
  TomorigProcess replay({"replay", src.string(), "--to", "tcp://127.0.0.1:*", "--rate", "1", "--sets", "0:2",
                         "--loop", "--timeout", "2"});
  const auto first_line = replay.wait_for_line("sending on");
  ASSERT_TRUE(first_line) << replay.err();
  TomorigProcess record({"record", "--from", endpoint_from(*first_line), "-o", out.string(), "--verbose",
                         "--idle-timeout", "60"});
  ASSERT_TRUE(record.wait_for_line("wrote set 0")) << record.err();
  ASSERT_TRUE(record.wait_for_line("wrote set 1")) << record.err();
  record.send_signal(SIGINT);
  ASSERT_EQ(record.wait(), 0) << record.err();
  EXPECT_NE(record.out().find("stopped: SIGINT"), std::string::npos) << record.out();
  // Replay, stopped with no recorder left, cannot deliver its session end: it says so and
  // still exits 0 (it was stopped on purpose).
  replay.send_signal(SIGINT);
  ASSERT_EQ(replay.wait(), 0) << replay.err();

  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  EXPECT_TRUE(storage::SessionReader(out).recording_complete());
  expect_same_sets(src, out, 2);
}

TEST_F(ReplayRecord, ReplayOfAMissingFileIsBadInput) {
  const CliResult r = run_tomorig("replay /nonexistent/session.h5 --to 'tcp://127.0.0.1:*'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/nonexistent/session.h5"), std::string::npos) << r.err;
}

TEST_F(ReplayRecord, ReplayOfACorruptFileIsBadInput) {
  TempDir tmp;
  const auto bad = tmp.write("bad.h5", "this is not an HDF5 file");
  const CliResult r = run_tomorig("replay " + shell_quoted(bad.string()) + " --to 'tcp://127.0.0.1:*'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("bad.h5"), std::string::npos) << r.err;
}

TEST_F(ReplayRecord, ReplayWithoutAReceiverFailsAndSaysSo) {
  const auto src = source();
  const CliResult r = run_tomorig("replay " + shell_quoted(src.string()) + " --to 'tcp://127.0.0.1:*' --timeout 0.3 --wait 0.3");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("no receiver"), std::string::npos) << r.err;
}

TEST_F(ReplayRecord, ReplayRejectsABadRateAndSetRange) {
  const auto src = source();
  const CliResult rate = run_tomorig("replay " + shell_quoted(src.string()) + " --rate fast");
  EXPECT_EQ(rate.exit_code, 2);
  EXPECT_NE(rate.err.find("--rate"), std::string::npos) << rate.err;
  const CliResult sets = run_tomorig("replay " + shell_quoted(src.string()) + " --sets 1:9");
  EXPECT_EQ(sets.exit_code, 2);
  EXPECT_NE(sets.err.find("--sets"), std::string::npos) << sets.err;
}

TEST_F(ReplayRecord, RecordRefusesToBindBeyondLoopback) {
  TempDir tmp;
  const auto out = tmp / "x.h5";
  const CliResult r = run_tomorig("record --bind --from tcp://0.0.0.0:5555 -o " + shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--allow-remote"), std::string::npos) << r.err;  // the flag record has
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

TEST_F(ReplayRecord, RecordWithNoSenderTimesOutWithoutAFile) {
  TempDir tmp;
  const auto out = tmp / "x.h5";
  const CliResult r = run_tomorig("record --bind --from 'tcp://127.0.0.1:*' --idle-timeout 0.3 -o " +
                                  shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("nothing was recorded"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace tomorig::testing
