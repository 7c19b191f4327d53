// End-to-end conventions of the command line: --help everywhere, exit codes 0/1/2.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cli_runner.h"

namespace tomorig::testing {
namespace {

TEST(Cli, TopLevelHelpListsCommandsAndExitCodes) {
  CliResult r = run_tomorig("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* name : {"run", "simulate", "import", "inspect", "config"})
    EXPECT_NE(r.out.find(name), std::string::npos) << name;
  EXPECT_NE(r.out.find("Exit codes"), std::string::npos);
}

TEST(Cli, EverySubcommandHasHelp) {
  const std::vector<std::string> commands = {"run", "simulate", "import", "inspect",
                                             "config", "config check", "config default"};
  for (const auto& c : commands) {
    CliResult r = run_tomorig(c + " --help");
    EXPECT_EQ(r.exit_code, 0) << c;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << c << ": " << r.out;
  }
}

TEST(Cli, UnknownCommandOrOptionIsBadUsage) {
  EXPECT_EQ(run_tomorig("frobnicate").exit_code, 2);
  EXPECT_EQ(run_tomorig("inspect --no-such-flag x.h5").exit_code, 2);
  EXPECT_EQ(run_tomorig("").exit_code, 2);  // a subcommand is required
}

TEST(Cli, VersionPrintsSomething) {
  CliResult r = run_tomorig("--version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_FALSE(r.out.empty());
}

}  // namespace
}  // namespace tomorig::testing
