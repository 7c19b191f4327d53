// `tomorig simulate --case calib-thesis --reduced`: the session holds one set per plane with
// each camera's target image, the truth names the planes and their true offsets, and the
// images detect to the truth's corners. Bad flag combinations are refused with exit code 2.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

class CalibThesisCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  TempDir dir_;
};

TEST_F(CalibThesisCli, WritesOneSetPerPlaneWithTruth) {
  const std::string out = (dir_ / "calib.h5").string();
  const CliResult r = run_tomorig("simulate --case calib-thesis --reduced --seed 4 --out " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("calib-thesis"), std::string::npos) << r.out;

  storage::SessionReader session(out);
  ASSERT_EQ(session.info().cameras.size(), 4u);
  EXPECT_EQ(session.info().cameras[0].width, 640);
  EXPECT_EQ(session.info().cameras[0].height, 540);
  ASSERT_EQ(session.set_count(), 7u);
  ASSERT_TRUE(session.has_truth());
  const storage::SessionTruth truth = session.truth();
  EXPECT_EQ(truth.case_name, "calib-thesis");
  EXPECT_EQ(truth.seed, 4u);
  ASSERT_EQ(truth.cameras.size(), 4u);
  const nlohmann::json p = nlohmann::json::parse(truth.flow_parameters);
  ASSERT_EQ(p["planes"].size(), 7u);
  EXPECT_EQ(p["inner_corners"][0], 22);
  EXPECT_EQ(p["square_mm"], 0.75);
  double largest = 0;
  for (std::size_t k = 0; k < 7; ++k) {
    EXPECT_EQ(p["planes"][k]["set"], k);
    EXPECT_DOUBLE_EQ(p["planes"][k]["z_nominal_mm"].get<double>(), -4.5 + 1.5 * k);
    for (int a = 0; a < 3; ++a) largest = std::max(largest, std::abs(p["planes"][k]["offset_um"][a].get<double>()));
  }
  EXPECT_GT(largest, 3.0);
  EXPECT_LE(largest, 22.0);

  // Set 3 (z = 0) of camera 2 shows the board; its corners are found.
  const FrameSet set = session.read_set(3);
  ASSERT_EQ(set.cameras.size(), 4u);
  ASSERT_TRUE(set.cameras[1].a.present());
  const calibration::TargetDetection d =
      calibration::detect_chessboard(set.cameras[1].a.image, {22, 21, 0.75}, 0.0, "camera 2, set 3");
  EXPECT_GT(d.points.size(), 300u);
}

TEST_F(CalibThesisCli, RefusesParticleFlags) {
  const std::string out = (dir_ / "x.h5").string();
  const CliResult r = run_tomorig("simulate --case calib-thesis --ppp 0.05 --out " + shell_quoted(out));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--ppp"), std::string::npos) << r.err;
  const CliResult r2 = run_tomorig("simulate --case tpiv-thesis --reduced --out " + shell_quoted(out));
  EXPECT_EQ(r2.exit_code, 2) << r2.err;
  EXPECT_NE(r2.err.find("calib-thesis only"), std::string::npos) << r2.err;
}

}  // namespace
}  // namespace tomorig::testing
