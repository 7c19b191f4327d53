// `tomorig simulate` end to end: runs the binary and checks exit codes, output and messages.
#include <sys/wait.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/storage/session_file.h"

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
  EXPECT_NE(r.output.find("set 1/1 rendered"), std::string::npos) << r.output;

  // The file holds what the library renders for the same case, ppp and seed, and its truth.
  const tomorig::storage::SessionReader reader(out);
  ASSERT_EQ(reader.set_count(), 1u);
  ASSERT_TRUE(reader.has_truth());
  const auto truth = reader.truth();
  EXPECT_EQ(truth.case_name, "tpiv-thesis");
  EXPECT_EQ(truth.flow_name, "taylor-green");
  EXPECT_EQ(truth.seed, 1u);
  EXPECT_DOUBLE_EQ(truth.ppp, 0.01);
  ASSERT_EQ(truth.cameras.size(), 4u);
  EXPECT_NEAR(truth.cameras[0].K[0], 100.0 / 0.0074, 1e-9);

  tomorig::sim::SimulationOptions options;
  options.ppp = 0.01;
  options.seed = 1;
  const auto expected = tomorig::sim::SimulatedRig(options).render_set(0);
  const auto truth_set = reader.truth_set(0);
  ASSERT_EQ(truth_set.particles_a.size(), expected.particles_a.size());
  EXPECT_DOUBLE_EQ(truth_set.particles_b[10].z, expected.particles_b[10].z);
  const auto frames = reader.read_set(0);
  ASSERT_EQ(frames.cameras.size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(frames.cameras[c].camera_id, expected.frames.cameras[c].camera_id);
    EXPECT_TRUE(frames.cameras[c].a.image.same_pixels(expected.frames.cameras[c].a.image)) << c;
    EXPECT_TRUE(frames.cameras[c].b.image.same_pixels(expected.frames.cameras[c].b.image)) << c;
  }
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

namespace {

TEST_F(SimulateCli, TwelveBitNoisySessionRecordsMono12) {
  const fs::path out = dir_ / "noisy.h5";
  const CliResult r =
      run("simulate --ppp 0.01 --sets 1 --seed 4 --noise --bit-depth 12 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const tomorig::storage::SessionReader reader(out);
  ASSERT_EQ(reader.info().cameras.size(), 4u);
  EXPECT_EQ(reader.info().cameras[0].pixel_format, tomorig::PixelFormat::Mono12);
  EXPECT_NE(reader.info().rig_config_toml.find("simulation.bit_depth = 12"), std::string::npos);
  const auto frames = reader.read_set(0);
  const tomorig::Image& img = frames.cameras[0].a.image;
  int max = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) max = std::max(max, static_cast<int>(img.value(x, y)));
  EXPECT_LE(max, 4095);
  EXPECT_GT(max, 0);
}

TEST_F(SimulateCli, BadBitDepthAndExistingOutputAreBadInput) {
  const fs::path out = dir_ / "x.h5";
  EXPECT_EQ(run("simulate --bit-depth 10 --out '" + out.string() + "'").exit_code, 2);
  std::ofstream(out) << "not a session";
  const CliResult r = run("simulate --ppp 0.01 --sets 1 --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.output;
}

}  // namespace
