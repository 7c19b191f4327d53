// `tomorig run`: the main job on the embedded default rig and on rig files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <csignal>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

TEST(RunCommand, DefaultRigRecordsASimulatedSessionWithTruth) {
  TempDir tmp;
  const auto out = tmp / "run.h5";
  CliResult r = run_tomorig("run --sets 1 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out));
  storage::SessionReader session(out);
  EXPECT_EQ(session.set_count(), 1u);
  ASSERT_EQ(session.info().cameras.size(), 4u);
  EXPECT_EQ(session.info().cameras[0].width, 512);
  EXPECT_TRUE(session.has_truth());
  EXPECT_NE(session.info().rig_config_toml.find("tpiv-thesis"), std::string::npos);
  EXPECT_EQ(session.missing_frames(), 0);
}

TEST(RunCommand, MalformedRigFileIsBadInputNamingTheKey) {
  TempDir tmp;
  const auto rig = tmp / "rig.toml";
  write_text(rig, "[[cameras]]\nid = \"cam0\"\npixel_format = \"Mono14\"\n");
  CliResult r = run_tomorig("run --config '" + rig.string() + "' --out '" + (tmp / "x.h5").string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pixel_format"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "x.h5"));
}

TEST(RunCommand, MissingRigFileIsBadUsage) {
  CliResult r = run_tomorig("run --config /nonexistent/rig.toml");
  EXPECT_EQ(r.exit_code, 2);
}

TEST(RunCommand, UnwritableOutputIsBadInputAndLeavesNothingBehind) {
  // A regular file used as the output folder cannot be written even by root.
  TempDir tmp;
  const auto not_a_folder = tmp / "plain-file";
  write_text(not_a_folder, "x");
  CliResult r = run_tomorig("run --sets 1 --out '" + (not_a_folder / "s.h5").string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("plain-file"), std::string::npos) << r.err;
  int entries = 0;
  for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(tmp.path())) ++entries;
  EXPECT_EQ(entries, 1);  // only the plain file itself
}

}  // namespace
}  // namespace tomorig::testing

// Ctrl-C during `tomorig run` ends the recording between sets with a complete session.
namespace tomorig::testing {
namespace {

TEST(RunCommandSignals, SigintLeavesACompleteSessionWithTheSetsRecorded) {
  TempDir dir;
  const auto out = dir / "run.h5";
  TomorigProcess run({"run", "--sets", "500", "-o", out.string()});
  ASSERT_TRUE(run.wait_for_line("recording: set 3/")) << run.err();
  run.send_signal(SIGINT);
  ASSERT_EQ(run.wait(), 0) << run.err();
  EXPECT_NE(run.err().find("stopped by SIGINT"), std::string::npos) << run.err();
  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  EXPECT_GE(session.set_count(), 3u);
  EXPECT_LT(session.set_count(), 500u);
  EXPECT_EQ(session.truth_set_count(), session.set_count());
}

}  // namespace
}  // namespace tomorig::testing
