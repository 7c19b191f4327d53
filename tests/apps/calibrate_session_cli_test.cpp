// `tomorig calibrate --session` on the simulated chessboard case (calib-thesis, reduced): the
// target images come from the session, the plane z from its truth's nominal positions. With
// --stage-correction the rational2 fit must reach the noise floor and the printed plane offsets
// must match the simulator's true traverse errors (both in the correction's gauge); without it
// the residual must be visibly larger. A particle session has no plane z: exit 2, naming
// --z-list.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/processing/calibration/traverse_correction.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

class CalibrateSessionCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  TempDir dir_;
};

constexpr const char* kChessboard = " --target chessboard --spacing 0.75 --corners 22,21";

// Mean forward residual (px) of `model` on each camera, from calibrate's --json report.
std::vector<double> forward_px(const nlohmann::json& report, const std::string& model) {
  std::vector<double> out;
  for (const auto& r : report["results"])
    if (r["model"] == model) out.push_back(r["forward_px"].get<double>());
  return out;
}

TEST_F(CalibrateSessionCli, StageCorrectionRecoversTraverseOffsetsAndLowersResiduals) {
  const std::string session = (dir_ / "calib.h5").string();
  const CliResult sim = run_tomorig("simulate --case calib-thesis --reduced --seed 4 --out " + shell_quoted(session));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;

  // The truth offsets, put into the gauge the correction reports in.
  const nlohmann::json truth = nlohmann::json::parse(storage::SessionReader(session).truth().flow_parameters);
  std::vector<Vec3d> true_offsets;
  std::vector<double> plane_z;
  for (const auto& p : truth["planes"]) {
    plane_z.push_back(p["z_nominal_mm"].get<double>());
    true_offsets.push_back({p["offset_um"][0].get<double>() * 1e-3, p["offset_um"][1].get<double>() * 1e-3,
                            p["offset_um"][2].get<double>() * 1e-3});
  }
  ASSERT_EQ(true_offsets.size(), 7u);
  calibration::remove_gauge(true_offsets, plane_z);

  const std::string corrected_toml = (dir_ / "corrected.toml").string();
  const CliResult corrected = run_tomorig("calibrate --session " + shell_quoted(session) + kChessboard +
                                          " --models pinhole,rational2 --stage-correction --json -o " +
                                          shell_quoted(corrected_toml));
  ASSERT_EQ(corrected.exit_code, 0) << corrected.err;
  EXPECT_TRUE(std::filesystem::exists(corrected_toml));
  const nlohmann::json with = nlohmann::json::parse(corrected.out);
  EXPECT_EQ(with["stored"], "rational2");
  const std::vector<double> with_px = forward_px(with, "rational2");
  ASSERT_EQ(with_px.size(), 4u);
  for (std::size_t c = 0; c < with_px.size(); ++c) EXPECT_LE(with_px[c], 0.04) << "camera " << c;

  const nlohmann::json& stage = with["stage_correction"];
  ASSERT_TRUE(stage.is_object()) << corrected.out;
  EXPECT_TRUE(stage["converged"].get<bool>());
  ASSERT_EQ(stage["planes"].size(), 7u);
  for (std::size_t k = 0; k < 7; ++k) {
    const auto& plane = stage["planes"][k];
    EXPECT_DOUBLE_EQ(plane["z_nominal_mm"].get<double>(), plane_z[k]);
    const Vec3d truth_um{true_offsets[k].x * 1e3, true_offsets[k].y * 1e3, true_offsets[k].z * 1e3};
    const double error_um = std::hypot(plane["offset_um"][0].get<double>() - truth_um.x,
                                       plane["offset_um"][1].get<double>() - truth_um.y,
                                       plane["offset_um"][2].get<double>() - truth_um.z);
    EXPECT_LT(error_um, 1.0) << "plane " << k << ": estimate " << plane["offset_um"].dump() << " um, truth ("
                             << truth_um.x << ", " << truth_um.y << ", " << truth_um.z << ") um";
    ASSERT_EQ(plane["per_camera_um"].size(), 4u);
    // A single view sees the in-plane y offset well (Table 6.3); its depth is poorly determined.
    for (const auto& camera : plane["per_camera_um"])
      EXPECT_NEAR(camera[1].get<double>(), truth_um.y, 1.0) << "plane " << k;
  }

  const CliResult plain = run_tomorig("calibrate --session " + shell_quoted(session) + kChessboard +
                                      " --models rational2 --json -o " + shell_quoted((dir_ / "plain.toml").string()));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const nlohmann::json without = nlohmann::json::parse(plain.out);
  EXPECT_TRUE(without["stage_correction"].is_null());
  const std::vector<double> without_px = forward_px(without, "rational2");
  ASSERT_EQ(without_px.size(), 4u);
  for (std::size_t c = 0; c < without_px.size(); ++c)
    EXPECT_GT(without_px[c], 3 * with_px[c]) << "camera " << c << ": the traverse errors should show without correction";
}

TEST_F(CalibrateSessionCli, ParticleSessionHasNoPlanePositions) {
  const std::string session = (dir_ / "particles.h5").string();
  ASSERT_EQ(run_tomorig("simulate --sets 1 --ppp 0.01 --seed 5 -o " + shell_quoted(session)).exit_code, 0);
  const std::string out = (dir_ / "x.toml").string();
  const CliResult r = run_tomorig("calibrate --session " + shell_quoted(session) + kChessboard + " -o " + shell_quoted(out));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("no plane z positions"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--z-list"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));

  // --z-list with the wrong count is refused too, naming the counts.
  const CliResult r2 = run_tomorig("calibrate --session " + shell_quoted(session) + kChessboard + " --z-list 0,1 -o " +
                                   shell_quoted(out));
  EXPECT_EQ(r2.exit_code, 2) << r2.err;
  EXPECT_NE(r2.err.find("1 sets"), std::string::npos) << r2.err;
}

}  // namespace
}  // namespace tomorig::testing
