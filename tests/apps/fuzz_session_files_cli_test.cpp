// Damaged session files through every reading command (issue 14): scripts/fuzz-session-files.sh
// with a representative count, each damaged file read by one command in turn (inspect, frames,
// preprocess, replay into record, reconstruct, process). Every run must end with exit 0 or 2:
// no signal, no hang past 10 s. The acceptance-size run (1000 flips + 200 truncations per file,
// every command on every file) is the same script without `rotate` (docs/reliability.md).
#include <gtest/gtest.h>

#include <string>

#include "cli_runner.h"

namespace tomorig::testing {
namespace {

TEST(FuzzSessionFilesCli, EveryDamagedFileEndsInExitZeroOrTwo) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
#ifdef TOMORIG_SANITIZED
  const std::string counts = "6 2";  // instrumented commands take several times longer
#else
  const std::string counts = "20 8";  // 56 runs: about 30 s on 2 quiet cores
#endif
  TempDir dir;
  const auto log = dir / "fuzz.txt";
  const std::string command = "bash " + shell_quoted(std::string(TOMORIG_SOURCE_DIR) + "/scripts/fuzz-session-files.sh") +
                              " " + shell_quoted(TOMORIG_BINARY) + " " + counts + " rotate >" +
                              shell_quoted(log.string()) + " 2>&1";
  const int status = std::system(command.c_str());
  const std::string report = read_text_file(log);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << report;
  EXPECT_NE(report.find("every run exited 0 or 2"), std::string::npos) << report;
  EXPECT_NE(report.find("  signal: 0"), std::string::npos) << report;
  EXPECT_NE(report.find("  timeout: 0"), std::string::npos) << report;
}

}  // namespace
}  // namespace tomorig::testing
