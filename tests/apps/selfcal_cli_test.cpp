// `tomorig selfcal` end to end: a simulated tpiv-thesis session, a calibration file with one
// camera misaligned (written through the calibration file API), the corrected file back.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/calibration/self_calibration.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

calibration::PinholeCamera truth_camera(const storage::TruthCamera& t) {
  calibration::PinholeParameters p;
  p.fx = t.K[0];
  p.cx = t.K[2];
  p.fy = t.K[4];
  p.cy = t.K[5];
  p.R = t.R;
  p.t = t.t;
  return calibration::PinholeCamera(p);
}

class SelfcalCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!tomorig_built()) return;
    dir_ = std::make_unique<TempDir>();
    session_ = (*dir_ / "s.h5").string();
    const CliResult r = run_tomorig("simulate --sets 1 --ppp 0.05 --seed 5 -o " + shell_quoted(session_));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // The truth cameras, camera 2 misaligned by 1.0 px and 0.2 deg, as a calibration file.
    const storage::SessionReader session(session_);
    const calibration::VolumeBounds slab{{-5, -5, -1.5}, {5, 5, 1.5}};
    std::vector<calibration::CameraCalibration> cal;
    for (const storage::TruthCamera& t : session.truth().cameras) {
      calibration::CameraCalibration c;
      c.id = static_cast<int>(cal.size());
      c.image_size = {t.width, t.height};
      c.model = std::make_shared<calibration::PinholeCamera>(truth_camera(t));
      c.report.model = "pinhole";
      if (c.id == 2) c.model = calibration::misaligned_camera(*c.model, c.image_size, slab, {-0.8, 0.6}, 0.2, c.report);
      cal.push_back(c);
    }
    misaligned_ = (*dir_ / "misaligned.toml").string();
    calibration::save_calibration(misaligned_, cal);
  }
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig is not built";
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::unique_ptr<TempDir> dir_;
  static std::string session_, misaligned_;
};
std::unique_ptr<TempDir> SelfcalCli::dir_;
std::string SelfcalCli::session_, SelfcalCli::misaligned_;

TEST_F(SelfcalCli, CorrectsTheMisalignedCameraAndWritesACalibrationThatMatchesTheTruth) {
  const std::string out = (*dir_ / "corrected.toml").string();
  const CliResult r = run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib " +
                                  shell_quoted(misaligned_) + " --json -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["converged"].get<bool>());
  const nlohmann::json& cam2 = j["cameras"][2];
  EXPECT_GT(cam2["before"]["volume"]["mean_px"].get<double>(), 0.4);
  EXPECT_LT(cam2["after"]["volume"]["mean_px"].get<double>(), 0.1);
  EXPECT_GT(cam2["truth_before_px"].get<double>(), 0.9);

  // The written file, judged by the session's truth rather than by the command's report.
  const auto corrected = calibration::load_calibration(out);
  ASSERT_EQ(corrected.size(), 4u);
  const storage::SessionReader session(session_);
  const storage::TruthSet truth = session.truth_set(0);
  for (const auto& c : corrected) {
    const calibration::PinholeCamera t = truth_camera(session.truth().cameras[static_cast<std::size_t>(c.id)]);
    EXPECT_LT(calibration::projection_difference(*c.model, t, truth.particles_a).mean_px, 0.1) << "camera " << c.id;
  }
}

TEST_F(SelfcalCli, TextReportAndTruthCalibration) {
  const std::string out = (*dir_ / "truth.toml").string();
  const CliResult r =
      run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib truth -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("already within tolerance"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("z-min layer"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out));
  // An existing output is not replaced without --overwrite.
  const CliResult again =
      run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib truth -o " + shell_quoted(out));
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("--overwrite"), std::string::npos) << again.err;
}

TEST_F(SelfcalCli, NonConvergenceExitsOneNamingTheCameraAndWritesNothing) {
  const std::string out = (*dir_ / "never.toml").string();
  const CliResult r = run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib " +
                                  shell_quoted(misaligned_) + " --max-iterations 0 -o " + shell_quoted(out));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("camera 2"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  // Issue 18: a search radius the disparities reach is named, with the radius to use.
  const CliResult small = run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib " +
                                      shell_quoted(misaligned_) + " --search-radius 0.8 --min-search-radius 0.8 "
                                      "--max-iterations 0 -o " + shell_quoted(out));
  EXPECT_NE(small.err.find("close to the 0.80 px search radius"), std::string::npos) << small.err;
  EXPECT_NE(small.err.find("rerun with --search-radius 1.6"), std::string::npos) << small.err;
}

TEST_F(SelfcalCli, BadInputExitsTwo) {
  const std::string out = (*dir_ / "bad.toml").string();
  EXPECT_EQ(run_tomorig("selfcal --session " + shell_quoted(session_) + " --sets 7 -o " + shell_quoted(out)).exit_code, 2);
  EXPECT_EQ(run_tomorig("selfcal --session " + shell_quoted(session_) + " --volume 1,2,3 -o " + shell_quoted(out)).exit_code,
            2);
  EXPECT_EQ(run_tomorig("selfcal --session " + shell_quoted(session_) + " --calib " +
                        shell_quoted((*dir_ / "nope.toml").string()) + " -o " + shell_quoted(out))
                .exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace tomorig::testing
