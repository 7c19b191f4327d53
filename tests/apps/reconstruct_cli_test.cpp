// `tomorig reconstruct` and `tomorig bench recon` end to end: a simulated session in, a volume
// file with its XDMF sidecar out, judged against the session's own ground truth.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/processing/quality/quality_report.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/volume_file.h"

namespace tomorig::testing {
namespace {

class ReconstructCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();  // shared by the suite: one simulated session for every test
    session_ = (*dir_ / "s.h5").string();
    const CliResult r = run_tomorig("simulate --sets 1 --ppp 0.01 --seed 3 -o " + shell_quoted(session_));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static std::unique_ptr<TempDir> dir_;
  static std::string session_;
};
std::unique_ptr<TempDir> ReconstructCli::dir_;
std::string ReconstructCli::session_;

TEST_F(ReconstructCli, WritesBothExposuresWithXdmfAndTheyMatchTheTruth) {
  const std::string out = (*dir_ / "v.h5").string();
  const CliResult r = run_tomorig("reconstruct --session " + shell_quoted(session_) +
                                  " --algorithm mlos --json -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["volumes"]["a"]["algorithm"], "mlos");
  EXPECT_GT(j["volumes"]["b"]["active_voxels"].get<double>(), 0);
  EXPECT_TRUE(std::filesystem::exists(*dir_ / "v.xdmf"));

  const storage::VolumeFileReader volumes(out);
  ASSERT_EQ(volumes.volumes().size(), 2u);
  EXPECT_EQ(volumes.info().source_session, session_);
  const storage::SessionReader session(session_);
  for (const auto& [name, exposure] : {std::pair{"a", 0}, std::pair{"b", 1}}) {
    const storage::StoredVolume& v = volumes.volume(name);
    EXPECT_EQ(v.grid.nx, 512);
    EXPECT_EQ(v.grid.nz, 160);
    EXPECT_EQ(v.attributes.exposure, exposure == 0 ? "A" : "B");
    // Judged against the true particles of its own exposure: the right exposure matches far
    // better than the other one (the particles moved by up to 5 voxel in between).
    const storage::TruthSet truth = session.truth_set(0);
    const SparseVolume volume = volumes.read_sparse(name);
    const double q_own = quality::evaluate_quality(volume, exposure == 0 ? truth.particles_a : truth.particles_b).q_global;
    const double q_other =
        quality::evaluate_quality(volume, exposure == 0 ? truth.particles_b : truth.particles_a).q_global;
    EXPECT_GT(q_own, 0.5) << name;
    EXPECT_GT(q_own, q_other + 0.1) << name;
  }
}

TEST_F(ReconstructCli, BadInputIsExitCode2WithAReason) {
  const std::string out = shell_quoted((*dir_ / "bad.h5").string());
  const std::string s = shell_quoted(session_);
  struct Case {
    std::string args, needle;
  };
  for (const Case& c : {Case{"--session nope.h5 -o " + out, "does not exist"},
                        Case{"--session " + s + " --set 7 -o " + out, "--set 7 is out of range"},
                        Case{"--session " + s + " --grid 12,x,3,0.1 -o " + out, "--grid '12,x,3,0.1' is not valid"},
                        Case{"--session " + s + " --algorithm nope -o " + out, "nope"},
                        Case{"--session " + s + " --calib missing.toml -o " + out, "missing.toml"}}) {
    const CliResult r = run_tomorig("reconstruct " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(*dir_ / "bad.h5")) << c.args;
  }
}

TEST(BenchReconCli, PrintsTheDocumentedJson) {
  // A reduced grid keeps this quick; accuracy figures come from the full case in benchmarks.
  const CliResult r = run_tomorig("bench recon --ppp 0.01 --algorithms mlos --grid 96,96,24,0.0195");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["case"], "tpiv-thesis");
  EXPECT_TRUE(j["machine"].contains("cores"));
  EXPECT_GT(j["memory_pass_seconds"].get<double>(), 0.0);
  ASSERT_EQ(j["results"].size(), 1u);
  const nlohmann::json& result = j["results"][0];
  for (const char* key : {"algorithm", "ppp", "iterations", "q_global", "q_windowed", "ghost_true_count_ratio",
                          "true_ghost_intensity_ratio", "position_rms_voxel", "detected_fraction", "seconds",
                          "peak_rss_mb", "active_voxels"})
    EXPECT_TRUE(result.contains(key)) << key;
  EXPECT_EQ(result["position_rms_voxel"].size(), 3u);
  EXPECT_GT(result["q_global"].get<double>(), 0.0);
  EXPECT_LE(result["q_global"].get<double>(), 1.0);
}

TEST(BenchReconCli, RepeatReportsWarmRoundsOfTheSameReconstruction) {
  const CliResult once = run_tomorig("bench recon --ppp 0.01 --algorithms fmart --iterations 2 --grid 96,96,24,0.0195");
  const CliResult thrice =
      run_tomorig("bench recon --ppp 0.01 --algorithms fmart --iterations 2 --repeat 3 --grid 96,96,24,0.0195");
  ASSERT_EQ(once.exit_code, 0) << once.err;
  ASSERT_EQ(thrice.exit_code, 0) << thrice.err;
  const nlohmann::json a = nlohmann::json::parse(once.out)["results"][0];
  const nlohmann::json b = nlohmann::json::parse(thrice.out)["results"][0];
  EXPECT_FALSE(a.contains("seconds_warm_median"));
  ASSERT_TRUE(b.contains("seconds_warm_median"));
  EXPECT_EQ(b["warm_rounds"], 2);
  EXPECT_GT(b["seconds_warm_min"].get<double>(), 0.0);
  EXPECT_LE(b["seconds_warm_min"].get<double>(), b["seconds_warm_median"].get<double>());
  // Repeating changes the timing, never the result: the judged volume is the same.
  EXPECT_EQ(a["active_voxels"], b["active_voxels"]);
  EXPECT_DOUBLE_EQ(a["q_global"].get<double>(), b["q_global"].get<double>());
  // Bad choices are refused as usage errors before any work, naming the option.
  for (const char* bad : {"--repeat 0", "--initial random", "--sigma-px -1", "--patch 99"}) {
    const CliResult r = run_tomorig(std::string("bench recon --grid 96,96,24,0.0195 ") + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.err;
    EXPECT_NE(r.err.find(std::string(bad).substr(0, std::string(bad).find(' '))), std::string::npos) << bad << "\n" << r.err;
  }
}

TEST(BenchPiv3dCli, ReducedTruthCaseMeetsTheNoiseFreeReferenceAndPrintsTheDocumentedJson) {
  const CliResult r = run_tomorig("bench piv3d --reduced --ppp 0.05 --source truth --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["results"].size(), 1u);
  const nlohmann::json& result = j["results"][0];
  for (const char* key : {"source", "ppp", "rms_voxel", "rms_magnitude_voxel", "rms_error_vector_voxel",
                          "valid_fraction", "seconds_correlation", "seconds_total"})
    EXPECT_TRUE(result.contains(key)) << key;
  EXPECT_EQ(result["source"], "truth");
  EXPECT_EQ(result["rms_voxel"].size(), 3u);
  // Against the analytic flow of Eq. 3.13 at the interior nodes: the thesis's noise-free
  // reference is 0.09 voxel (issue 5).
  // reference is 0.09 voxel (issue 5). Met also by the stricter length of the error vector;
  // the magnitude error (|d| - |d_true|, the thesis's figure) can never exceed it.
  EXPECT_LE(result["rms_error_vector_voxel"].get<double>(), 0.09);
  EXPECT_LE(result["rms_magnitude_voxel"].get<double>(), result["rms_error_vector_voxel"].get<double>());
  EXPECT_GT(result["rms_magnitude_voxel"].get<double>(), 0.0);
  EXPECT_GE(result["valid_fraction"].get<double>(), 0.99);
  // Issue 19: the time breakdown per pass and the FFT floor measured in the same run. The truth
  // volumes are sparse (~3 % occupied), so the deformation passes correlate directly.
  EXPECT_GT(result["seconds_fft_floor"].get<double>(), 0.0);
  EXPECT_GT(result["ratio_to_fft_floor"].get<double>(), 0.0);
  const nlohmann::json& passes = result["correlation_report"]["passes"];
  ASSERT_EQ(passes.size(), 4u);
  for (const nlohmann::json& pass : passes) {
    for (const char* key : {"seconds", "seconds_deformation", "seconds_windows", "seconds_validation",
                            "thread_seconds_load", "thread_seconds_correlation", "thread_seconds_peak",
                            "empty_windows", "fft_fallbacks", "occupied_fraction"})
      EXPECT_TRUE(pass.contains(key)) << key;
    EXPECT_LE(pass["seconds_deformation"].get<double>() + pass["seconds_windows"].get<double>() +
                  pass["seconds_validation"].get<double>(),
              pass["seconds"].get<double>() + 1e-6);
  }
  EXPECT_EQ(passes[0]["method"], "fft");     // the binned pass: no predictor, no pre-search
  EXPECT_EQ(passes[1]["method"], "direct");  // integer offset: around the binned pre-search's peak
  EXPECT_LT(passes[1]["fft_fallbacks"].get<double>(), 0.05 * passes[1]["nodes"][0].get<double>() *
                                                          passes[1]["nodes"][1].get<double>() *
                                                          passes[1]["nodes"][2].get<double>());
  EXPECT_EQ(passes[3]["method"], "direct");  // residual after deformation, sparse volumes
  EXPECT_LT(passes[3]["occupied_fraction"].get<double>(), 0.08);
}

// Refused up front, before the case is rendered.
TEST(BenchPiv3dCli, RefusesABadPruneFractionNamingIt) {
  const CliResult r = run_tomorig("bench piv3d --reduced --ppp 0.01 --source fmart --prune 2");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("prune_fraction"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("rendering"), std::string::npos) << r.err;
}

TEST(BenchPiv3dCli, RefusesABadGaussianWidthOrRelaxationNamingIt) {
  for (const char* bad : {"--gaussian-sigma 0", "--gaussian-sigma 3", "--relaxation 2.5"}) {
    const CliResult r = run_tomorig(std::string("bench piv3d --reduced --ppp 0.01 --source fmart ") + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.err;
    EXPECT_NE(r.err.find(std::string(bad).substr(0, std::string(bad).find(' '))), std::string::npos) << bad << "\n" << r.err;
    EXPECT_EQ(r.err.find("rendering"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace tomorig::testing
