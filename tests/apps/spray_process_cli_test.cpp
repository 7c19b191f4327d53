// The spray back-end through the product on `tomorig simulate --case spray-thesis` sessions
// (issue 20, thesis Sect. 7.4-7.5): the session carries its rig, so `process` takes it; the
// mean intensity volume over the sets lies where the simulator put the droplets; blobs get a
// size class from their own intensity, compared with the truth's.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/simulators/spray.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/storage/volume_file.h"

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

// Spray statistics (Sect. 7.4): the mean intensity volume over the sets lies where the
// simulator's droplets are - its centroid near theirs, weighted by the light each removes (~d^2),
// and its 90 % extent around them - written as a volume file, PNG slices and a JSON summary.
TEST_F(SprayProcess, TheMeanIntensityVolumeLiesWhereTheTruthsDropletsAre) {
  TempDir dir;
  const fs::path session = dir / "s.h5", mean = dir / "mean.h5", slices = dir / "slices";
  const CliResult sim = run_tomorig("simulate --case spray-thesis --reduced --sets 3 --seed 2 -o " + shell_quoted(session.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string grid = " --grid 100,80,60,0.16";  // the whole droplet volume, 16 x 12.8 x 9.6 mm
  const CliResult rec = run_tomorig("reconstruct " + shell_quoted(session.string()) +
                                    " --mean --chain shadow-a --psf truth --algorithm ment --exposure a" + grid +
                                    " --slices " + shell_quoted(slices.string()) + " -o " + shell_quoted(mean.string()) +
                                    " --json");
  ASSERT_EQ(rec.exit_code, 0) << rec.err;
  const json j = json::parse(rec.out).at("mean");
  EXPECT_EQ(j.at("volumes"), 3);
  EXPECT_EQ(j.at("slices").size(), 8u);
  for (const json& f : j.at("slices")) EXPECT_TRUE(fs::exists(f.get<std::string>())) << f;
  EXPECT_TRUE(fs::exists(dir / "mean.xdmf"));
  const storage::VolumeFileReader volumes(mean);
  const DenseVolume v = volumes.read_dense("mean");
  EXPECT_EQ(v.grid.nx, 100);

  // The truth: every droplet of the 3 sets at pulse A inside the grid, weighted by d^2 (the
  // session records the diameters of its first set only; the case regenerates them all).
  sim::SprayOptions options;
  options.reduced = true;
  options.seed = 2;
  const sim::SprayCase spray = sim::make_spray_thesis_case(options);
  const storage::SessionReader s(session);
  double w = 0, cx = 0, cy = 0, cz = 0;
  for (std::uint64_t k = 0; k < 3; ++k) {
    const std::vector<sim::Droplet> drops = sim::spray_droplets(spray, k);
    ASSERT_EQ(drops.size(), s.truth_set(k).particles_a.size());
    EXPECT_NEAR(drops[0].a.x, s.truth_set(k).particles_a[0].x, 1e-6);
    for (const sim::Droplet& drop : drops) {
      const Vec3d p = drop.a;
      if (std::abs(p.x) > 7.9 || std::abs(p.y) > 6.3 || std::abs(p.z) > 4.7) continue;
      const double weight = drop.d_um * drop.d_um;
      w += weight;
      cx += weight * p.x;
      cy += weight * p.y;
      cz += weight * p.z;
    }
  }
  cx /= w, cy /= w, cz /= w;
  const json& c = j.at("centroid_mm");
  // The jet enters at the corner x = -8, y = -6.5 mm and bends along +y: its centroid is far
  // from the grid's centre, so agreement here is not by chance.
  ASSERT_GT(std::hypot(cx, cy), 1.0) << cx << " " << cy;
  EXPECT_NEAR(c[0].get<double>(), cx, 0.6) << j.dump();
  EXPECT_NEAR(c[1].get<double>(), cy, 0.6) << j.dump();
  EXPECT_NEAR(c[2].get<double>(), cz, 0.6) << j.dump();
  const json& lo = j.at("extent_mm").at("low");
  const json& hi = j.at("extent_mm").at("high");
  for (int a = 0; a < 3; ++a) {
    const double centre = a == 0 ? cx : a == 1 ? cy : cz;
    EXPECT_LT(lo[a].get<double>(), centre) << a;
    EXPECT_GT(hi[a].get<double>(), centre) << a;
  }
  // An existing output is refused before any work.
  const CliResult again = run_tomorig("reconstruct " + shell_quoted(session.string()) + " --mean" + grid +
                                      " --psf truth -o " + shell_quoted(mean.string()));
  EXPECT_EQ(again.exit_code, 2) << again.err;
  EXPECT_NE(again.err.find("--overwrite"), std::string::npos) << again.err;
  // The mean's options belong to it, and one set's to one set.
  const fs::path other = dir / "other.h5";
  const CliResult sets_alone = run_tomorig("reconstruct " + shell_quoted(session.string()) + " --sets 2" + grid +
                                           " -o " + shell_quoted(other.string()));
  EXPECT_EQ(sets_alone.exit_code, 2) << sets_alone.err;
  EXPECT_NE(sets_alone.err.find("--mean"), std::string::npos) << sets_alone.err;
  const CliResult one_set = run_tomorig("reconstruct " + shell_quoted(session.string()) + " --mean --set 1" + grid +
                                        " -o " + shell_quoted(other.string()));
  EXPECT_EQ(one_set.exit_code, 2) << one_set.err;
  EXPECT_NE(one_set.err.find("--set does not apply"), std::string::npos) << one_set.err;
  // An empty selection is refused, not averaged over nothing.
  const CliResult none = run_tomorig("reconstruct " + shell_quoted(session.string()) + " --mean --sets 2:2" + grid +
                                     " --psf truth -o " + shell_quoted(other.string()));
  EXPECT_EQ(none.exit_code, 2) << none.err;
  EXPECT_NE(none.err.find("the range is empty"), std::string::npos) << none.err;
  EXPECT_FALSE(fs::exists(other));
}

// Each blob's size class from its own light (optics/droplet_size.h), at the reconstruction's
// scale fitted on one simulated session and passed on to another: its class agrees with the
// truth's for most droplets, and nearly always within one class.
TEST_F(SprayProcess, BlobsGetTheirOwnSizeClassFromTheirIntensity) {
  TempDir dir;
  const fs::path calib = dir / "calib.h5", other = dir / "other.h5", a = dir / "a.json", b = dir / "b.json";
  for (const auto& [file, seed] : {std::pair{calib, 5}, std::pair{other, 6}}) {
    const CliResult sim = run_tomorig("simulate --case spray-thesis --reduced --sets 1 --seed " + std::to_string(seed) +
                                      " -o " + shell_quoted(file.string()));
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  const std::string grid = " --grid 160,128,100,0.04";
  const CliResult fit = run_tomorig("bench spray " + shell_quoted(calib.string()) + grid + " --json " + shell_quoted(a.string()));
  ASSERT_EQ(fit.exit_code, 0) << fit.err;
  EXPECT_NE(fit.out.find("size class estimated from each blob's intensity"), std::string::npos) << fit.out;
  const json ja = json::parse(read_text(a)).at("size_estimate");
  EXPECT_EQ(ja.at("shadow_scale_source"), "fitted on this session's truth");
  const double scale = ja.at("shadow_scale").get<double>();
  ASSERT_GT(scale, 0);
  const CliResult use = run_tomorig("bench spray " + shell_quoted(other.string()) + grid + " --shadow-scale " +
                                    std::to_string(scale) + " --json " + shell_quoted(b.string()));
  ASSERT_EQ(use.exit_code, 0) << use.err;
  const json jb = json::parse(read_text(b)).at("size_estimate");
  EXPECT_EQ(jb.at("shadow_scale_source"), "--shadow-scale");
  EXPECT_GE(jb.at("matched").get<int>(), 100) << jb.dump();
  EXPECT_GE(jb.at("same_class_fraction").get<double>(), 0.5) << jb.dump();
  EXPECT_GE(jb.at("within_one_class_fraction").get<double>(), 0.9) << jb.dump();
  // The confusion matrix holds every matched droplet once; the large ones are told apart.
  int total = 0;
  for (const json& row : jb.at("confusion"))
    for (const json& n : row.at("estimated")) total += n.get<int>();
  EXPECT_EQ(total, jb.at("matched").get<int>());
  // Each class's mean estimate is near the class's centre (within 35 %) and grows with it.
  const json classes = json::parse(read_text(b)).at("classes");
  double previous = 0;
  int judged = 0;
  for (const json& c : classes) {
    if (c.at("detected").get<int>() < 5) continue;
    const double centre = 0.5 * (c.at("d_um")[0].get<double>() + c.at("d_um")[1].get<double>());
    const double estimate = c.at("d_est_mean_um").get<double>();
    EXPECT_NEAR(estimate / centre, 1.0, 0.35) << c.dump();
    EXPECT_GT(estimate, previous) << c.dump();
    previous = estimate;
    ++judged;
  }
  EXPECT_GE(judged, 4);
}

}  // namespace
}  // namespace tomorig::testing
