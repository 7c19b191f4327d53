// `tomorig simulate` end to end: runs the binary and checks exit codes, output and messages.
#include <sys/wait.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

class SimulateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(TOMORIG_BINARY)) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
    dir_ = fs::temp_directory_path() /
           ("tomorig_simulate_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }

  CliResult run(const std::string& args) const {
    const fs::path log = dir_ / "output.txt";
    const std::string command = std::string("'") + TOMORIG_BINARY + "' " + args + " > '" + log.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    CliResult r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    r.output = ss.str();
    return r;
  }

  fs::path dir_;
};

TEST_F(SimulateCli, WritesASession) {
  const fs::path out = dir_ / "tmp.h5";
  const CliResult r = run("simulate --case tpiv-thesis --ppp 0.01 --sets 1 --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(out)) << r.output;
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
}

TEST_F(SimulateCli, UnknownCaseIsBadInputNamingTheCase) {
  const CliResult r = run("simulate --case nope --ppp 0.01 --sets 1 --out '" + (dir_ / "x.h5").string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("nope"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("tpiv-thesis"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "x.h5"));
}

TEST_F(SimulateCli, PppOutOfRangeIsBadInput) {
  for (const char* ppp : {"0", "1.5"}) {
    const CliResult r = run(std::string("simulate --case tpiv-thesis --ppp ") + ppp + " --sets 1 --out '" +
                      (dir_ / "x.h5").string() + "'");
    EXPECT_EQ(r.exit_code, 2) << ppp << ": " << r.output;
    EXPECT_NE(r.output.find("ppp"), std::string::npos) << r.output;
  }
}

}  // namespace
