// `tomorig calibrate --points` end to end: correspondences made from known pinhole cameras go
// in, and the calibration file that comes out must reproduce those cameras' projections; every
// kind of bad input is an error naming what is wrong. Finally the file must drive
// `tomorig reconstruct` on a simulated session.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

using calibration::PinholeCamera;
using Distortion = std::function<Vec2d(Vec2d)>;

// Rows "camera,X,Y,Z,x,y" for a grid of X, Y in [-half, half] on each z plane, per camera.
// The first camera gets index `first_index`.
std::string csv_rows(const std::vector<PinholeCamera>& cameras, const std::vector<double>& planes, double half,
                     int per_side, const Distortion& distort = nullptr, std::size_t first_index = 0) {
  std::string rows;
  for (std::size_t c = 0; c < cameras.size(); ++c)
    for (const double z : planes)
      for (int i = 0; i < per_side; ++i)
        for (int j = 0; j < per_side; ++j) {
          const Vec3d world{-half + 2 * half * i / (per_side - 1), -half + 2 * half * j / (per_side - 1), z};
          Vec2d pixel = cameras[c].project(world);
          if (distort) pixel = distort(pixel);
          rows += fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", first_index + c, world.x, world.y, world.z, pixel.x,
                              pixel.y);
        }
  return rows;
}

void write_file(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

std::vector<PinholeCamera> stereo_pair() {
  return {PinholeCamera::yawed(-25, 60, 10, 600, 512, 512), PinholeCamera::yawed(25, 60, 10, 600, 512, 512)};
}

class CalibrateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  std::string write_points(const std::string& rows, const std::string& name = "points.csv") {
    const auto path = dir_ / name;
    write_file(path, "camera,X,Y,Z,x,y\n" + rows);
    return shell_quoted(path.string());
  }
  TempDir dir_;
};

TEST_F(CalibrateCli, StoredModelsReproduceTheTrueCamerasAndTheReportIsNoiseFree) {
  const auto cameras = stereo_pair();
  const std::string points = write_points("# a comment line, then a blank line\n\n" +
                                          csv_rows(cameras, {-4, -2, 0, 2, 4}, 10, 7));
  const std::string out = (dir_ / "calib.toml").string();
  const CliResult r = run_tomorig("calibrate --points " + points + " --models pinhole,rational2 --image-size 512,512 --json -o " +
                                  shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["stored"], "rational2");
  EXPECT_EQ(j["out"], out);
  ASSERT_EQ(j["results"].size(), 4u);  // 2 cameras x 2 models
  for (const nlohmann::json& result : j["results"]) {
    EXPECT_EQ(result["points"], 5 * 7 * 7);
    EXPECT_TRUE(result["converged"].get<bool>());
    EXPECT_LT(result["forward_px"].get<double>(), 1e-4) << result.dump();
    EXPECT_LT(result["reverse_um"].get<double>(), 1e-2) << result.dump();
  }

  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(loaded[c].id, static_cast<int>(c));
    EXPECT_EQ(loaded[c].image_size.width, 512);
    EXPECT_EQ(loaded[c].model->model_name(), "rational2");
    // Held-out points: between the grid nodes and between the planes.
    for (const Vec3d world : {Vec3d{1.3, -2.7, 0.9}, Vec3d{-7.1, 5.5, -3.3}, Vec3d{8.2, 8.9, 3.1}}) {
      const Vec2d truth = cameras[c].project(world);
      const Vec2d fitted = loaded[c].model->project(world);
      EXPECT_LT(std::hypot(fitted.x - truth.x, fitted.y - truth.y), 1e-3) << "camera " << c;
    }
  }
}

TEST_F(CalibrateCli, StoreOptionAndTextReportAndPerCameraSizes) {
  const auto cameras = stereo_pair();
  const std::string points = write_points(csv_rows(cameras, {-2, 0, 2}, 10, 6));
  const std::string out = (dir_ / "calib.toml").string();
  const CliResult r = run_tomorig("calibrate --points " + points +
                                  " --models dlt,pinhole --store dlt --camera-size 0=512,512 --camera-size 1=640,480 -o " +
                                  shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("forward px"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("reverse um"), std::string::npos) << r.out;
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 2u);
  EXPECT_EQ(loaded[0].model->model_name(), "dlt");
  EXPECT_EQ(loaded[1].image_size.width, 640);
  EXPECT_EQ(loaded[1].image_size.height, 480);
  const Vec3d world{3.3, -1.1, 1.7};
  const Vec2d truth = cameras[1].project(world), fitted = loaded[1].model->project(world);
  EXPECT_LT(std::hypot(fitted.x - truth.x, fitted.y - truth.y), 1e-3);
}

// Issue 23: an existing calibration was replaced without a word. Now it is refused before any
// fit, the file untouched, unless --overwrite is given.
TEST_F(CalibrateCli, AnExistingCalibrationIsReplacedOnlyWithOverwrite) {
  const std::string points = write_points(csv_rows(stereo_pair(), {-2, 0, 2}, 10, 6));
  const auto out = dir_ / "calib.toml";
  write_file(out, "# the calibration of yesterday's run\n");
  const CliResult refused = run_tomorig("calibrate --points " + points + " --models pinhole --image-size 512,512 -o " + shell_quoted(out.string()));
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_NE(refused.err.find("already exists"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--overwrite"), std::string::npos) << refused.err;
  EXPECT_EQ(read_text_file(out), "# the calibration of yesterday's run\n");
  const CliResult replaced = run_tomorig("calibrate --points " + points + " --models pinhole --image-size 512,512 --overwrite -o " +
                                         shell_quoted(out.string()));
  ASSERT_EQ(replaced.exit_code, 0) << replaced.err;
  EXPECT_EQ(calibration::load_calibration(out.string()).size(), 2u);
}

TEST_F(CalibrateCli, BadInputIsAnErrorNamingTheCameraOrTheLine) {
  const auto cameras = stereo_pair();
  const std::string good = csv_rows(cameras, {-2, 0, 2}, 10, 6);
  const std::string only_first = csv_rows({cameras[0]}, {-2, 0, 2}, 10, 6);
  // Camera 1 with 5 points only.
  std::string few = only_first;
  for (int k = 0; k < 5; ++k) few += fmt::format("1,{},{},{},{},{}\n", k, 2 * k, k % 2, 100 + k, 200 + 3 * k);
  // Camera 1 on the plane z = 0 only.
  const std::string flat = only_first + csv_rows({cameras[1]}, {0}, 10, 6, nullptr, 1);
  // Camera 1 with world points on one line.
  std::string line = only_first;
  for (int k = 0; k < 10; ++k) line += fmt::format("1,{},{},{},{},{}\n", k, k, k, 10 * k, 20 * k + (k % 3));
  // The line after the header and the good rows.
  const std::string bad_line = fmt::format(".csv:{}:", 2 + std::count(good.begin(), good.end(), '\n'));
  struct Case {
    std::string name, rows, args, needle;
    int exit_code;
  };
  const std::vector<Case> cases = {
      {"few", few, "--models pinhole", "camera 1: too few points", 2},
      {"flat", flat, "--models pinhole", "camera 1: all 36 points lie on one plane (z = 0", 2},
      {"line", line, "--models pinhole", "camera 1: degenerate geometry", 2},
      {"model", good, "--models pinhole,fisheye", "unknown camera model 'fisheye'", 2},
      {"store", good, "--models pinhole --store dlt", "--store dlt", 2},
      {"size", good, "--models pinhole --image-size 512", "--image-size '512' is not valid", 2},
      {"csv", good + "1,2.0,oops,3,4,5\n", "--models pinhole", bad_line + " column 3 (Y): 'oops' is not a finite number", 2},
      {"fields", good + "1,2.0,3\n", "--models pinhole", bad_line + " 3 fields, expected 6", 2},
  };
  for (const Case& c : cases) {
    const std::string points = write_points(c.rows, c.name + ".csv");
    const auto out = dir_ / (c.name + ".toml");
    const CliResult r = run_tomorig("calibrate --points " + points + " " + c.args +
                                    (c.name == "size" ? "" : " --image-size 512,512") + " -o " + shell_quoted(out.string()));
    EXPECT_EQ(r.exit_code, c.exit_code) << c.name << "\n" << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << c.name << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.name;
  }
  // No image size at all.
  const CliResult r = run_tomorig("calibrate --points " + write_points(good) + " -o " + shell_quoted((dir_ / "x.toml").string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("camera 0: no image size"), std::string::npos) << r.err;
  // A bad header names the column.
  write_file(dir_ / "header.csv", "camera,X,Y,depth,x,y\n");
  const CliResult h = run_tomorig("calibrate --points " + shell_quoted((dir_ / "header.csv").string()) +
                                  " --image-size 512,512 -o " + shell_quoted((dir_ / "x.toml").string()));
  EXPECT_EQ(h.exit_code, 2);
  EXPECT_NE(h.err.find("header.csv:1: column 4: unknown header 'depth'"), std::string::npos) << h.err;
}

TEST_F(CalibrateCli, AFitThatDoesNotConvergeIsARuntimeFailureNamingTheCamera) {
  // Lens-like radial distortion, so the rational2 LM has work to do beyond its DLT start.
  const auto distort = [](Vec2d p) {
    const double dx = p.x - 255.5, dy = p.y - 255.5, k = 1 + 2e-6 * (dx * dx + dy * dy);
    return Vec2d{255.5 + dx * k, 255.5 + dy * k};
  };
  const std::string points = write_points(csv_rows(stereo_pair(), {-4, -2, 0, 2, 4}, 10, 7, distort));
  const auto out = dir_ / "calib.toml";
  const CliResult r = run_tomorig("calibrate --points " + points +
                                  " --models rational2 --max-iterations 1 --image-size 512,512 -o " + shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("camera 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("did not converge"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--max-iterations"), std::string::npos) << r.err;  // the flag the user can change
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(CalibrateCli, TheFileDrivesReconstructOnASimulatedSession) {
  const std::string session = (dir_ / "s.h5").string();
  const CliResult sim = run_tomorig("simulate --sets 1 --ppp 0.01 --seed 5 -o " + shell_quoted(session));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const storage::SessionTruth truth = storage::SessionReader(session).truth();
  std::vector<PinholeCamera> cameras;
  std::string sizes;
  for (std::size_t c = 0; c < truth.cameras.size(); ++c) {
    const storage::TruthCamera& t = truth.cameras[c];
    calibration::PinholeParameters p;
    p.fx = t.K[0], p.cx = t.K[2], p.fy = t.K[4], p.cy = t.K[5], p.R = t.R, p.t = t.t;
    cameras.emplace_back(p);
    sizes += fmt::format(" --camera-size {}={},{}", c, t.width, t.height);
  }
  const std::string points = write_points(csv_rows(cameras, {-1.5, -0.5, 0.5, 1.5}, 5, 6));
  const std::string calib = (dir_ / "calib.toml").string();
  const CliResult cal = run_tomorig("calibrate --points " + points + " --models pinhole" + sizes + " -o " + shell_quoted(calib));
  ASSERT_EQ(cal.exit_code, 0) << cal.err;
  const CliResult rec = run_tomorig("reconstruct --session " + shell_quoted(session) + " --calib " + shell_quoted(calib) +
                                    " --algorithm mlos --grid 64,64,16,0.0195 --json -o " +
                                    shell_quoted((dir_ / "v.h5").string()));
  ASSERT_EQ(rec.exit_code, 0) << rec.err;
  EXPECT_EQ(nlohmann::json::parse(rec.out)["volumes"]["a"]["algorithm"], "mlos");
}

}  // namespace
}  // namespace tomorig::testing
