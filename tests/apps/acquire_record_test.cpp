// `tomorig acquire` and `tomorig record` as the two halves of a split rig: separate processes
// talking over loopback TCP. Acquire binds a free port ("tcp://127.0.0.1:*") and prints it;
// record connects to it. The frames recorded must be the simulator's, bit for bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "child_process.h"
#include "cli_runner.h"
#include "session_compare.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

// The endpoint from acquire's first stderr line "acquire: sending on tcp://127.0.0.1:PORT, ...".
std::string endpoint_from(const std::string& line) {
  const std::string marker = "sending on ";
  const auto begin = line.find(marker);
  if (begin == std::string::npos) return {};
  const auto start = begin + marker.size();
  return line.substr(start, line.find(',', start) - start);
}

// Every set of `recorded` has the pixels, Δt and trigger index of the same set of `reference`
// (the simulator's own rendering of the rig; its timestamps come from the nominal rate, the
// rig's from the trigger device, so those are not compared).
void expect_frames_of(const std::filesystem::path& reference, const std::filesystem::path& recorded,
                      std::uint64_t sets) {
  const storage::SessionReader ref(reference);
  const storage::SessionReader rec(recorded);
  ASSERT_EQ(rec.set_count(), sets);
  ASSERT_EQ(rec.info().cameras.size(), ref.info().cameras.size());
  EXPECT_EQ(rec.missing_frames(), 0);
  for (std::uint64_t k = 0; k < sets; ++k) {
    const FrameSet a = ref.read_set(k);
    const FrameSet b = rec.read_set(k);
    EXPECT_EQ(b.trigger_index, k);
    EXPECT_EQ(b.dt_ns, a.dt_ns) << "set " << k;
    ASSERT_EQ(a.cameras.size(), b.cameras.size());
    for (std::size_t c = 0; c < a.cameras.size(); ++c) {
      EXPECT_EQ(a.cameras[c].camera_id, b.cameras[c].camera_id);
      for (const Exposure e : {Exposure::A, Exposure::B})
        EXPECT_TRUE(a.cameras[c][e].image.same_pixels(b.cameras[c][e].image))
            << "set " << k << " camera " << c << " frame " << (e == Exposure::A ? 'A' : 'B');
    }
  }
}

TEST(AcquireRecord, SplitRigRecordsFramesBitIdenticalToTheSimulator) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir dir;
  const auto reference = dir / "reference.h5";
  const auto recorded = dir / "recorded.h5";
  const CliResult sim = run_tomorig("simulate --sets 3 -o " + shell_quoted(reference.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;

  TomorigProcess acquire(
      {"acquire", "--sets", "3", "--pace", "max", "--to", "tcp://127.0.0.1:*", "--status", "none", "--wait", "30"});
  const auto line = acquire.wait_for_line("acquire: sending on");
  ASSERT_TRUE(line) << acquire.err();
  const std::string endpoint = endpoint_from(*line);
  ASSERT_FALSE(endpoint.empty()) << *line;

  TomorigProcess record({"record", "--from", endpoint, "-o", recorded.string(), "--idle-timeout", "30"});
  ASSERT_EQ(record.wait(), 0) << record.err();
  ASSERT_EQ(acquire.wait(), 0) << acquire.err();
  EXPECT_NE(acquire.out().find("acquired and sent 3 sets"), std::string::npos) << acquire.out();
  EXPECT_NE(acquire.err().find("acquire: set 3/3"), std::string::npos) << acquire.err();  // the status line
  expect_frames_of(reference, recorded, 3);
  EXPECT_TRUE(storage::SessionReader(recorded).recording_complete());
}

// The split rig writes the file `tomorig run` writes for the same rig: /config, root
// attributes, cameras with pixel pitch, the truth of every set, the frames; and record ends by
// itself at the sender's end of acquisition, with no --sets and no idle timeout to end it.
TEST(AcquireRecord, SplitRigFileMatchesARunFileOfTheSameRigAndRecordStopsByItself) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir dir;
  const auto run_file = dir / "run.h5";
  const auto recorded = dir / "recorded.h5";
  const CliResult run = run_tomorig("run --sets 3 --pace max --status none -o " + shell_quoted(run_file.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;

  TomorigProcess acquire(
      {"acquire", "--sets", "3", "--pace", "max", "--to", "tcp://127.0.0.1:*", "--status", "none", "--wait", "30"});
  const auto line = acquire.wait_for_line("acquire: sending on");
  ASSERT_TRUE(line) << acquire.err();
  // A user's command has neither --sets nor --idle-timeout; the generous idle timeout only keeps
  // a broken build from hanging the test (and its "stopped" message would fail it).
  TomorigProcess record({"record", "--from", endpoint_from(*line), "-o", recorded.string(), "--idle-timeout", "120"});
  ASSERT_EQ(record.wait(), 0) << record.err();
  ASSERT_EQ(acquire.wait(), 0) << acquire.err();
  EXPECT_NE(record.out().find("recorded 3 sets"), std::string::npos) << record.out();
  EXPECT_NE(record.out().find("the sender ended the session: completed"), std::string::npos) << record.out();
  EXPECT_EQ(record.out().find("idle-timeout"), std::string::npos) << record.out();
  EXPECT_NE(record.err().find("4 cameras"), std::string::npos) << record.err();
  EXPECT_NE(record.err().find("with truth"), std::string::npos) << record.err();

  expect_same_session_metadata(run_file, recorded, /*same_creation_time=*/false);
  expect_frames_of(run_file, recorded, 3);
}

TEST(AcquireRecord, VanishedCameraIsCountedAndRecordedAsMissing) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir dir;
  const auto recorded = dir / "recorded.h5";
  TomorigProcess acquire({"acquire", "--sets", "4", "--pace", "max", "--to", "tcp://127.0.0.1:*", "--status", "none",
                          "--wait", "30", "--inject-fault", "cam2:vanish-after=2", "--on-camera-loss", "continue"});
  const auto line = acquire.wait_for_line("acquire: sending on");
  ASSERT_TRUE(line) << acquire.err();
  TomorigProcess record(
      {"record", "--from", endpoint_from(*line), "-o", recorded.string(), "--idle-timeout", "30"});
  ASSERT_EQ(record.wait(), 0) << record.err();
  ASSERT_EQ(acquire.wait(), 0) << acquire.err();
  EXPECT_NE(acquire.err().find("camera cam2 vanished at trigger 2"), std::string::npos) << acquire.err();
  EXPECT_NE(acquire.out().find("4 lost frames, 2 incomplete sets"), std::string::npos) << acquire.out();
  const storage::SessionReader session(recorded);
  ASSERT_EQ(session.set_count(), 4u);
  EXPECT_EQ(session.missing_frames(), 4);
  EXPECT_EQ(session.incomplete_sets(), 2);
  for (std::uint64_t k = 0; k < 4; ++k) {
    const storage::SetRecord r = session.set_record(k);
    for (std::size_t c = 0; c < 4; ++c)
      for (int e = 0; e < 2; ++e) EXPECT_EQ(r.frame_present[c][e], !(c == 2 && k >= 2)) << "set " << k << " cam " << c;
  }
}

}  // namespace
}  // namespace tomorig::testing
