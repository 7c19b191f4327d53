// The spray back-end through the product on `tomorig simulate --case spray-thesis` sessions
// (issue 20, thesis Sect. 7.4-7.5): the session carries its rig, so `process` takes it; the
// mean intensity volume over the sets lies where the simulator put the droplets; blobs get a
// size class from their own intensity, compared with the truth's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class SprayProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
};

// The simulated session holds the rig that records the same case live: `tomorig run` on the
// stored config renders the same frames, and `process` runs on the session as on a recording.
TEST_F(SprayProcess, SimulatedSessionsHoldTheirRigSoProcessTakesThem) {
  TempDir dir;
  const fs::path session = dir / "s.h5", live = dir / "live.h5", rig = dir / "rig.toml", results = dir / "r.h5";
  const CliResult sim = run_tomorig("simulate --case spray-thesis --reduced --sets 1 --seed 4 --spray hollow-cone -o " +
                                    shell_quoted(session.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::string config;
  {
    const storage::SessionReader s(session);
    config = s.info().rig_config_toml;
  }
  EXPECT_NE(config.find("seed = 4"), std::string::npos) << config;
  EXPECT_NE(config.find("spray = \"hollow-cone\""), std::string::npos) << config;
  std::ofstream(rig) << config;
  const CliResult run = run_tomorig("run --config " + shell_quoted(rig.string()) + " --sets 1 --status none -o " +
                                    shell_quoted(live.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  {
    const storage::SessionReader a(session), b(live);
    const FrameSet x = a.read_set(0), y = b.read_set(0);
    EXPECT_EQ(x.dt_ns, y.dt_ns);
    for (std::size_t c = 0; c < 4; ++c) {
      EXPECT_TRUE(x.cameras[c].a.image.same_pixels(y.cameras[c].a.image)) << c;
      EXPECT_TRUE(x.cameras[c].b.image.same_pixels(y.cameras[c].b.image)) << c;
    }
  }
  const CliResult process = run_tomorig("process " + shell_quoted(session.string()) +
                                        " --chain shadow-b --psf truth --grid 80,64,48,0.1 --window 16,16,16 -o " +
                                        shell_quoted(results.string()));
  ASSERT_EQ(process.exit_code, 0) << process.err;
  const storage::ResultsReader r(results);
  ASSERT_EQ(r.set_indices().size(), 1u);
  EXPECT_EQ(r.read_set(0).dt_ns, 1700);
}

}  // namespace
}  // namespace tomorig::testing
