// End to end: `tomorig config ...` run as a user would, checking exit codes and output.
// The tomorig binary is built with the whole project; if it is not there (a partial build of
// just this suite), the tests skip and say so.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_runner.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config {
namespace {

namespace fs = std::filesystem;

using testing::CliResult;
using testing::run_tomorig;
using RunResult = CliResult;
std::string quoted(const std::string& s) { return testing::shell_quoted(s); }

class ConfigCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!testing::tomorig_built()) GTEST_SKIP() << "tomorig is not built (" << TOMORIG_BINARY << "); build target tomorig";
  }
  RunResult run(const std::string& args) const { return run_tomorig(args); }
  fs::path write(const std::string& name, const std::string& text) const { return dir_.write(name, text); }

  testing::TempDir dir_;
};

TEST_F(ConfigCli, DefaultPrintsTheEmbeddedRigVerbatim) {
  const RunResult r = run("config default");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, default_rig_toml());
  EXPECT_EQ(r.err, "");
}

TEST_F(ConfigCli, CheckOfTheDefaultRigIsOk) {
  const fs::path file = write("rig.toml", default_rig_toml());
  const RunResult r = run("config check " + quoted(file.string()));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind(file.string() + ": ok", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("4 cameras"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one line expected:\n" << r.out;
}

TEST_F(ConfigCli, CheckReportsEveryIssueWithKeyAndLine) {
  const fs::path file = write("bad.toml",
                              "[[cameras]]\n"
                              "id = \"a\"\n"
                              "backend = \"simulated\"\n"
                              "pixel_format = \"Mono14\"\n"
                              "[cameras.roi]\n"
                              "width = 0\n"
                              "height = 8\n"
                              "[grid]\n"
                              "nxx = 4\n");
  const RunResult r = run("config check " + quoted(file.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  const std::string f = file.string();
  EXPECT_NE(r.err.find("3 problems"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\n" + f + ":4: cameras[0].pixel_format: \"Mono14\" is not supported (Mono8, Mono12, Mono16)\n"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("\n" + f + ":6: cameras[0].roi.width: 0 must be > 0\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\n" + f + ":9: grid.nxx: unknown key, did you mean \"nx\"?"), std::string::npos) << r.err;
}

TEST_F(ConfigCli, CheckReportsSyntaxErrors) {
  const fs::path file = write("syntax.toml", "name = \"x\"\n[[cameras]\nid = 1\n");
  const RunResult r = run("config check " + quoted(file.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(file.string() + ":2:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("invalid TOML"), std::string::npos) << r.err;
}

TEST_F(ConfigCli, CheckOfAMissingFileNamesIt) {
  const std::string missing = (dir_ / "nope.toml").string();
  const RunResult r = run("config check " + quoted(missing));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find(missing), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("does not exist"), std::string::npos) << r.err;
}

TEST_F(ConfigCli, ConfigNeedsASubcommand) {
  const RunResult r = run("config");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE((r.out + r.err).find("subcommand"), std::string::npos) << r.out << r.err;
}

TEST_F(ConfigCli, CheckNeedsAFile) {
  const RunResult r = run("config check");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE((r.out + r.err).find("FILE"), std::string::npos) << r.out << r.err;
}

TEST_F(ConfigCli, HelpDescribesTheSubcommands) {
  const RunResult r = run("config --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("check"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("default"), std::string::npos) << r.out;
  const RunResult check = run("config check --help");
  EXPECT_EQ(check.exit_code, 0);
  EXPECT_NE(check.out.find("FILE"), std::string::npos) << check.out;
}

}  // namespace
}  // namespace tomorig::config
