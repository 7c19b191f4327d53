// `tomorig stages` and `tomorig run --stage`: chains of stages fed by a live rig or a recorded
// session, through the commands a user would type.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include "cli_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

TEST(StagesCli, ListsEveryRegisteredStage) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  const CliResult r = run_tomorig("stages");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* type : {"recorder", "frame-stats", "backend"})
    EXPECT_NE(r.out.find(type), std::string::npos) << r.out;
}

TEST(StagesCli, ALiveRunFeedsItsStagesAndARecorderStageCopiesASessionExactly) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir tmp;
  const auto run_out = tmp / "run.h5";
  const CliResult run = run_tomorig("run --sets 3 --pace max --status none --stage frame-stats:full_scale=4095 -o " +
                                    shell_quoted(run_out.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("run: stage frame-stats: "), std::string::npos) << run.err;

  const auto copy = tmp / "copy.h5";
  const CliResult replay = run_tomorig("stages --session " + shell_quoted(run_out.string()) +
                                       " --stage recorder:out=" + copy.string() + ",compression=bitshuffle-lz4 --json");
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  EXPECT_NE(replay.out.find("\"processed\": 3"), std::string::npos) << replay.out;
  const storage::SessionReader original(run_out), copied(copy);
  ASSERT_EQ(copied.set_count(), original.set_count());
  EXPECT_EQ(copied.info().rig_config_toml, original.info().rig_config_toml);
  EXPECT_TRUE(copied.has_truth());
  const FrameSet a = original.read_set(2), b = copied.read_set(2);
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  EXPECT_EQ(std::memcmp(a.cameras[1].b.image.data(), b.cameras[1].b.image.data(), a.cameras[1].b.image.size_bytes()),
            0);
}

TEST(StagesCli, ABadStageSettingIsBadInputNamingTheKeyBeforeAnythingRuns) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir tmp;
  const CliResult r = run_tomorig("run --sets 1 --status none --stage frame-stats:ful_scale=255 -o " +
                                  shell_quoted((tmp / "x.h5").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("ful_scale"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "x.h5"));
  EXPECT_FALSE(std::filesystem::exists(tmp / "x.h5.partial"));
}

}  // namespace
}  // namespace tomorig::testing
