// `tomorig calibrate --images / --image-list`: dot-grid target images rendered from known
// pinhole cameras go in; the detected points, the fitted models and the per-plane report must
// match those cameras; bad input (different image sizes within a camera, one plane, too few
// points, no origin marker, a fit that does not converge) is an error naming camera and plane.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "../processing/calibration/dot_grid_render.h"
#include "cli_runner.h"
#include "tomorig/processing/calibration/calibration_file.h"
#include "tomorig/processing/calibration/lens_camera.h"
#include "tomorig/simulators/dot_target.h"
#include "tomorig/simulators/window_view.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::testing {
namespace {

namespace fs = std::filesystem;
using calibration::PinholeCamera;
using dot_grid_test::TargetDrawing;

constexpr int kWidth = 320, kHeight = 288;
const std::vector<double> kPlanes = {-3, -1, 1, 3};

std::vector<PinholeCamera> cameras() {
  return {dot_grid_test::oblique_camera(20, 5, 1, 14, 300, kWidth, kHeight),
          dot_grid_test::oblique_camera(-20, -5, -2, 14, 300, kWidth, kHeight)};
}

class CalibrateImagesCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
  // DIR/cam<c>/<z>mm_cam<c>.png for every camera and plane.
  fs::path render_folder(const std::string& name, const std::vector<double>& planes, const TargetDrawing& target = {},
                         int width = kWidth) {
    const fs::path root = dir_ / name;
    const auto cams = cameras();
    for (std::size_t c = 0; c < cams.size(); ++c) {
      fs::create_directories(root / fmt::format("cam{}", c));
      for (const double z : planes)
        storage::write_png(root / fmt::format("cam{}", c) / fmt::format("{}mm_cam{}.png", z, c),
                           dot_grid_test::render_target(cams[c], target, z, width, kHeight, 8, 7 + c));
    }
    return root;
  }
  // The staggered plate of the two-level tests (2 mm nearest-dot spacing, a second level 0.5 mm
  // behind the first, a filled square origin and a +x triangle), rendered like render_folder at
  // z = -2, 0, 2 mm; camera c's noise seed is first_seed + c.
  fs::path render_staggered_two_level_plate(const std::string& name, unsigned first_seed) {
    sim::DotPlate plate;
    plate.spec.spacing_mm = 2.0;
    plate.spec.lattice = calibration::DotLattice::staggered;
    plate.spec.level_offset_mm = -0.5;
    plate.triangle_site = 2;
    plate.noise_counts = 8;
    const fs::path root = dir_ / name;
    const auto cams = cameras();
    for (std::size_t c = 0; c < cams.size(); ++c) {
      fs::create_directories(root / fmt::format("cam{}", c));
      for (const double z : {-2.0, 0.0, 2.0}) {
        plate.seed = first_seed + c;
        storage::write_png(root / fmt::format("cam{}", c) / fmt::format("{}mm_cam{}.png", z, c),
                           sim::render_dot_plate(cams[c], plate, z, kWidth, kHeight));
      }
    }
    return root;
  }
  TempDir dir_;
};

TEST_F(CalibrateImagesCli, FolderOfDotImagesCalibratesToTheTrueCameras) {
  const fs::path images = render_folder("calibration", kPlanes);
  const std::string out = (dir_ / "calib.toml").string(), points = (dir_ / "points.csv").string();
  const CliResult r = run_tomorig("calibrate --images " + shell_quoted(images.string()) +
                                  " --spacing 2 --models pinhole,soloff3 --store pinhole --json --points-out " +
                                  shell_quoted(points) + " -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["results"].size(), 4u);  // 2 cameras x 2 models
  for (const nlohmann::json& result : j["results"]) {
    EXPECT_EQ(result["planes"], 4);
    EXPECT_GT(result["points"].get<int>(), 4 * 60) << result.dump();
    EXPECT_LT(result["forward_px"].get<double>(), 0.1) << result.dump();
    ASSERT_EQ(result["per_plane"].size(), 4u);
    EXPECT_EQ(result["per_plane"][0]["z_mm"], -3.0);
    for (const nlohmann::json& plane : result["per_plane"]) EXPECT_LT(plane["forward_px"].get<double>(), 0.1);
  }
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 2u);
  const auto truth = cameras();
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(loaded[c].image_size.width, kWidth);
    EXPECT_EQ(loaded[c].image_size.height, kHeight);
    for (const Vec3d world : {Vec3d{1.3, -2.7, 0.4}, Vec3d{-4.1, 3.5, -2.2}, Vec3d{5.2, 4.9, 2.6}}) {
      const Vec2d a = truth[c].project(world), b = loaded[c].model->project(world);
      EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 0.1) << "camera " << c;
    }
  }
  EXPECT_TRUE(fs::exists(points));
}

TEST_F(CalibrateImagesCli, ImageListWithBlackDots) {
  TargetDrawing target;
  target.white_dots = false;
  const fs::path images = render_folder("black", {-2, 2}, target);
  std::ofstream(dir_ / "list.csv") << "camera,z,file\n"
                                   << "0,-2,black/cam0/-2mm_cam0.png\n0,2,black/cam0/2mm_cam0.png\n"
                                   << "1,-2,black/cam1/-2mm_cam1.png\n1,2,black/cam1/2mm_cam1.png\n";
  const CliResult r = run_tomorig("calibrate --image-list " + shell_quoted((dir_ / "list.csv").string()) +
                                  " --spacing 2 --dots black --models pinhole --json -o " +
                                  shell_quoted((dir_ / "c.toml").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const nlohmann::json& result : nlohmann::json::parse(r.out)["results"])
    EXPECT_LT(result["forward_px"].get<double>(), 0.1) << result.dump();
}

TEST_F(CalibrateImagesCli, BadInputNamesCameraAndPlane) {
  const fs::path good = render_folder("good", kPlanes);
  const std::string out = (dir_ / "x.toml").string();
  auto run = [&](const std::string& images, const std::string& extra) {
    return run_tomorig("calibrate --images " + shell_quoted(images) + " " + extra + " -o " + shell_quoted(out));
  };
  struct Case {
    std::string name, images, args;
    int exit_code;
    std::vector<std::string> needles;
  };
  // Camera 1 has one image of another size.
  const fs::path mixed = render_folder("mixed", kPlanes);
  storage::write_png(mixed / "cam1" / "1mm_cam1.png",
                     dot_grid_test::render_target(cameras()[1], {}, 1, kWidth + 16, kHeight));
  // Camera 0 on one plane only.
  const fs::path flat = render_folder("flat", {0});
  // No origin marker.
  TargetDrawing unmarked;
  unmarked.marker_line_mm = 0;
  const fs::path no_marker = render_folder("nomarker", {-1, 1}, unmarked);
  // A file whose name holds no z.
  const fs::path unnamed = render_folder("unnamed", {-1, 1});
  fs::copy_file(unnamed / "cam0" / "1mm_cam0.png", unnamed / "cam0" / "target.png");

  const std::vector<Case> cases = {
      {"sizes", mixed.string(), "--spacing 2 --models pinhole", 2, {"camera 1, plane z = 1 mm", "same size"}},
      {"flat", flat.string(), "--spacing 2 --models pinhole", 2, {"camera 0", "one plane (z = 0"}},
      {"few", good.string(), "--spacing 2 --models pinhole --min-points-per-plane 1000", 2,
       {"camera 0, plane z = -3 mm", "too few target points"}},
      {"marker", no_marker.string(), "--spacing 2 --models pinhole", 2, {"camera 0, plane z = -1 mm", "origin marker"}},
      {"name", unnamed.string(), "--spacing 2 --models pinhole", 2, {"target.png", "<z>mm"}},
      {"spacing", good.string(), "--models pinhole", 2, {"--spacing"}},
      {"polarity", good.string(), "--spacing 2 --dots grey", 2, {"--dots 'grey'"}},
      {"converge", good.string(), "--spacing 2 --models rational2 --max-iterations 1", 1,
       {"camera 0", "did not converge", "--max-iterations"}},
  };
  for (const Case& c : cases) {
    const CliResult r = run(c.images, c.args);
    EXPECT_EQ(r.exit_code, c.exit_code) << c.name << "\n" << r.err;
    for (const std::string& needle : c.needles) EXPECT_NE(r.err.find(needle), std::string::npos) << c.name << "\n" << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.name;
  }
  // Two sources at once.
  const CliResult both = run_tomorig("calibrate --images " + shell_quoted(good.string()) + " --points p.csv --spacing 2 -o " +
                                     shell_quoted(out));
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("exactly one of"), std::string::npos) << both.err;
}


// A staggered plate with dots on two depth levels, a filled square origin and a +x triangle,
// rendered by the simulator and described by a target file: every camera calibrates to its
// true camera within 0.05 px; the same images described by --spacing alone (a square lattice)
// are refused naming the staggered lattice and the sqrt(2).
TEST_F(CalibrateImagesCli, StaggeredTwoLevelPlateFromATargetFile) {
  const fs::path images = render_staggered_two_level_plate("plate", 11);
  const auto cams = cameras();
  const fs::path target = dir_ / "plate.toml";
  std::ofstream(target) << "kind = \"dots\"\npitch_mm = 2.0\nlattice = \"staggered\"\nlevel_offset_mm = -0.5\n"
                           "y_axis = \"down\"\n";
  const std::string out = (dir_ / "plate_calib.toml").string();
  const fs::path overlay = dir_ / "overlay";
  const CliResult r = run_tomorig("calibrate --images " + shell_quoted(images.string()) + " --target-file " +
                                  shell_quoted(target.string()) + " --models pinhole --json --overlay " +
                                  shell_quoted(overlay.string()) + " -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Where the origin went, and how the axes were set, for every image; and the overlay shows it.
  EXPECT_NE(r.err.find("camera 1, plane z = 2 mm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("origin (filled square) at ("), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("set by the triangle"), std::string::npos) << r.err;
  for (std::size_t c = 0; c < cams.size(); ++c) {
    const Image drawn = storage::read_image(overlay / fmt::format("cam{}_2mm.png", c));
    ASSERT_EQ(drawn.width(), kWidth);
    const Vec2d o = cams[c].project({0, 0, 2});
    // The origin's ring (9 px) is drawn in white over an image dimmed to <= 160.
    EXPECT_GT(drawn.value(static_cast<int>(std::lround(o.x + 9)), static_cast<int>(std::lround(o.y))), 200) << c;
  }
  const CliResult again = run_tomorig("calibrate --images " + shell_quoted(images.string()) + " --target-file " +
                                      shell_quoted(target.string()) + " --overlay " + shell_quoted(overlay.string()) +
                                      " -o " + shell_quoted((dir_ / "again.toml").string()));
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("exists; give --overwrite"), std::string::npos) << again.err;
  for (const nlohmann::json& result : nlohmann::json::parse(r.out)["results"]) {
    EXPECT_EQ(result["planes"], 6) << result.dump();  // 3 plane positions x 2 levels
    EXPECT_GT(result["points"].get<int>(), 3 * 150) << result.dump();
    EXPECT_LT(result["forward_px"].get<double>(), 0.05) << result.dump();
  }
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c)
    for (const Vec3d world : {Vec3d{1.3, -2.7, 0.4}, Vec3d{-4.1, 3.5, -2.2}, Vec3d{5.2, 4.9, 1.6}}) {
      const Vec2d a = cams[c].project(world), b = loaded[c].model->project(world);
      EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 0.05) << "camera " << c;
    }

  const CliResult square = run_tomorig("calibrate --images " + shell_quoted(images.string()) +
                                       " --spacing 2 --models pinhole -o " + shell_quoted((dir_ / "sq.toml").string()));
  EXPECT_EQ(square.exit_code, 2) << square.err;
  EXPECT_NE(square.err.find("staggered"), std::string::npos) << square.err;
  EXPECT_NE(square.err.find("sqrt(2)"), std::string::npos) << square.err;
  EXPECT_FALSE(fs::exists(dir_ / "sq.toml"));

  const CliResult both = run_tomorig("calibrate --images " + shell_quoted(images.string()) + " --target-file " +
                                     shell_quoted(target.string()) + " --spacing 2 -o " + shell_quoted(out + "2"));
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("--spacing do(es) not go with it"), std::string::npos) << both.err;
  std::ofstream(dir_ / "bad.toml") << "kind = \"dots\"\npitch_mm = 2.0\nlevel_offset_mm = 1\n";
  const CliResult bad = run_tomorig("calibrate --images " + shell_quoted(images.string()) + " --target-file " +
                                    shell_quoted((dir_ / "bad.toml").string()) + " -o " + shell_quoted(out + "3"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("level_offset_mm needs lattice = \"staggered\""), std::string::npos) << bad.err;
}

// The same kind of two-level plate, its dot depths given dot by dot in a side file
// (--target-z) instead of as a level offset: every camera calibrates to its true camera within
// 0.05 px; a malformed file, a file that misses a detected point, and a level offset given
// beside the file are refused (exit 2) naming the file and line or the point, nothing written.
TEST_F(CalibrateImagesCli, TwoLevelPlateWithPointDepthsFromASideFile) {
  const fs::path images = render_staggered_two_level_plate("plate_z", 21);
  const auto cams = cameras();
  // Every site of both levels, the second 0.5 mm below the first; BOM and CRLF as from Excel.
  const fs::path depths = dir_ / "depths.csv";
  {
    std::ofstream f(depths, std::ios::binary);
    f << "\xEF\xBB\xBFX,Y,Z\r\n# site x, y in mm; z relative to the plate\r\n";
    for (int i = -15; i <= 15; ++i)
      for (int j = -15; j <= 15; ++j) {
        f << fmt::format("{},{},0\r\n", 2.0 * i, 2.0 * j);
        f << fmt::format("{},{},-0.5\r\n", 2.0 * i + 1, 2.0 * j + 1);
      }
  }
  const std::string common = "calibrate --images " + shell_quoted(images.string()) +
                             " --lattice staggered --spacing 2 --y-axis down --models pinhole --json";
  const std::string out = (dir_ / "z_calib.toml").string();
  const CliResult r = run_tomorig(common + " --target-z " + shell_quoted(depths.string()) + " -o " + shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("point z from --target-z"), std::string::npos) << r.err;
  for (const nlohmann::json& result : nlohmann::json::parse(r.out)["results"]) {
    EXPECT_EQ(result["planes"], 6) << result.dump();  // 3 plate positions x 2 depths from the file
    EXPECT_LT(result["forward_px"].get<double>(), 0.05) << result.dump();
  }
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c)
    for (const Vec3d world : {Vec3d{1.3, -2.7, 0.4}, Vec3d{-4.1, 3.5, -2.2}, Vec3d{5.2, 4.9, 1.6}}) {
      const Vec2d a = cams[c].project(world), b = loaded[c].model->project(world);
      EXPECT_LT(std::hypot(a.x - b.x, a.y - b.y), 0.05) << "camera " << c;
    }

  // A malformed file: named by line, refused before any detection.
  std::ofstream(dir_ / "bad_z.csv") << "X,Y,Z\n0,0,0\n2,2,deep\n";
  const CliResult bad = run_tomorig(common + " --target-z " + shell_quoted((dir_ / "bad_z.csv").string()) + " -o " +
                                    shell_quoted(out + "2"));
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("bad_z.csv:3: Z 'deep' is not a number"), std::string::npos) << bad.err;
  std::ofstream(dir_ / "header_z.csv") << "x,y,depth\n0,0,0\n";
  const CliResult header = run_tomorig(common + " --target-z " + shell_quoted((dir_ / "header_z.csv").string()) +
                                       " -o " + shell_quoted(out + "2"));
  EXPECT_EQ(header.exit_code, 2) << header.err;
  EXPECT_NE(header.err.find("header_z.csv:1: header column 'x' is unknown"), std::string::npos) << header.err;
  // A file for another plate: the first level only, so the second level's dots are missing.
  {
    std::ofstream f(dir_ / "one_level.csv");
    f << "X,Y,Z\n";
    for (int i = -15; i <= 15; ++i)
      for (int j = -15; j <= 15; ++j) f << fmt::format("{},{},0\n", 2.0 * i, 2.0 * j);
  }
  const CliResult mismatch = run_tomorig(common + " --target-z " + shell_quoted((dir_ / "one_level.csv").string()) +
                                         " -o " + shell_quoted(out + "2"));
  EXPECT_EQ(mismatch.exit_code, 2) << mismatch.err;
  EXPECT_NE(mismatch.err.find("is not in --target-z"), std::string::npos) << mismatch.err;
  EXPECT_NE(mismatch.err.find("mm: the target point ("), std::string::npos) << mismatch.err;
  const CliResult both = run_tomorig(common + " --level-offset -0.5 --target-z " + shell_quoted(depths.string()) +
                                     " -o " + shell_quoted(out + "2"));
  EXPECT_EQ(both.exit_code, 2) << both.err;
  EXPECT_NE(both.err.find("does not go with it"), std::string::npos) << both.err;
  const CliResult points = run_tomorig("calibrate --points " + shell_quoted(depths.string()) + " --target-z " +
                                       shell_quoted(depths.string()) + " --image-size 100,100 -o " + shell_quoted(out + "2"));
  EXPECT_EQ(points.exit_code, 2) << points.err;
  EXPECT_NE(points.err.find("--target-z gives the z of the points detected in target images"), std::string::npos)
      << points.err;
  EXPECT_FALSE(fs::exists(out + "2"));
}

// Issue 18 end to end on rendered images: a dot plate on 7 planes seen through a lens with
// barrel distortion, and through 10 mm of glass into water (1.0 / 1.49 / 1.33), each drawn by
// the simulator (sim::render_dot_plate through the true view) and calibrated by `tomorig
// calibrate --images` alone. The stored pinhole_distortion / refractive model must be within
// 0.05 px of the true view at points not used in the fit (between the planes and the dots).
class CalibrateRenderedOpticsCli : public CalibrateImagesCli {
 protected:
  static constexpr int kW = 480, kH = 400;
  fs::path render(const std::string& name, const sim::BackProjection& view) {
    sim::DotPlate plate;
    plate.spec.spacing_mm = 2.0;
    plate.triangle_site = 2;
    plate.noise_counts = 8;
    plate.samples = 3;  // 9 rays per pixel: each ray through the window is a Newton solve
    const fs::path root = dir_ / name;
    fs::create_directories(root / "cam0");
    for (int k = 0; k < 7; ++k) {
      const double z = -6.0 + 2.0 * k;
      plate.seed = 40 + k;
      storage::write_png(root / "cam0" / fmt::format("{}mm_cam0.png", z), sim::render_dot_plate(view, plate, z, kW, kH));
    }
    return root;
  }
  // Largest distance between the stored model and the truth over random points in the box
  // the planes span.
  static double held_out_error(const calibration::CameraModel& stored, const std::function<Vec2d(const Vec3d&)>& truth) {
    std::mt19937_64 rng(21);
    std::uniform_real_distribution<double> xy(-6.0, 6.0), z(-6.0, 6.0);
    double worst = 0;
    for (int k = 0; k < 300; ++k) {
      const Vec3d world{xy(rng), xy(rng), z(rng)};
      const Vec2d a = truth(world), b = stored.project(world);
      worst = std::max(worst, std::hypot(a.x - b.x, a.y - b.y));
    }
    return worst;
  }
};

TEST_F(CalibrateRenderedOpticsCli, LensDistortionThroughRenderedImages) {
  const PinholeCamera pinhole = dot_grid_test::oblique_camera(22, 6, 2, 22, 300, kW, kH);
  calibration::LensDistortion barrel;
  barrel.k1 = -9;  // ideal radius ~0.047 at the image corners (fx = 6600 px): 2 % barrel, ~6 px there
  const calibration::LensCamera lens(pinhole.parameters(), barrel);
  const fs::path images = render("lens", [&](const Vec2d& p, double z) { return lens.back_project(p, z); });
  const std::string out = (dir_ / "lens.toml").string();
  const CliResult r = run_tomorig("calibrate --images " + shell_quoted(images.string()) +
                                  " --spacing 2 --y-axis down --models pinhole,pinhole_distortion --json -o " +
                                  shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].model->model_name(), "pinhole_distortion");
  double corner = 0;
  for (const Vec3d w : {Vec3d{-6, -6, 0}, Vec3d{6, 6, 0}, Vec3d{-6, 6, 6}, Vec3d{6, -6, -6}})
    corner = std::max(corner, std::hypot(lens.project(w).x - pinhole.project(w).x, lens.project(w).y - pinhole.project(w).y));
  EXPECT_GT(corner, 1.0);  // within the held-out box; the distortion the plain pinhole cannot follow
  const double held_out = held_out_error(*loaded[0].model, [&](const Vec3d& w) { return lens.project(w); });
  EXPECT_LT(held_out, 0.05);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::printf("lens rig: pinhole_distortion held-out max %.4f px vs truth; fit RMS pinhole %.3f px, "
              "pinhole_distortion %.4f px\n",
              held_out, j["results"][0]["forward_rms_px"].get<double>(), j["results"][1]["forward_rms_px"].get<double>());
  EXPECT_GT(j["results"][0]["forward_rms_px"].get<double>(), 0.2) << j["results"][0].dump();  // pinhole
}

TEST_F(CalibrateRenderedOpticsCli, RefractiveThroughRenderedImagesBehindGlassIntoWater) {
  calibration::FlatWindow window;
  window.normal = {std::sin(0.3 * M_PI / 180), 0, std::cos(0.3 * M_PI / 180)};
  window.medium_face_mm = -20;
  window.thickness_mm = 10;
  window.n_air = 1.0, window.n_window = 1.49, window.n_medium = 1.33;
  const sim::WindowView view{dot_grid_test::oblique_camera(20, 4, 1, 22, 300, kW, kH), window};
  const fs::path images = render("window", [&](const Vec2d& p, double z) { return view.back_project(p, z); });
  const std::string out = (dir_ / "window.toml").string();
  const CliResult r = run_tomorig("calibrate --images " + shell_quoted(images.string()) +
                                  " --spacing 2 --y-axis down --models pinhole,refractive --window-thickness 10 "
                                  "--indices 1.0,1.49,1.33 --window-face -21 --window-normal 0,0,1 --json -o " +
                                  shell_quoted(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto loaded = calibration::load_calibration(out);
  ASSERT_EQ(loaded.size(), 1u);
  EXPECT_EQ(loaded[0].model->model_name(), "refractive");
  const double held_out = held_out_error(*loaded[0].model, [&](const Vec3d& w) { return view.project(w); });
  EXPECT_LT(held_out, 0.05);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  std::printf("window rig: refractive held-out max %.4f px vs truth; fit RMS pinhole %.3f px, refractive %.4f px\n",
              held_out, j["results"][0]["forward_rms_px"].get<double>(), j["results"][1]["forward_rms_px"].get<double>());
  EXPECT_GT(j["results"][0]["forward_rms_px"].get<double>(), 0.1) << j["results"][0].dump();  // pinhole
}

}  // namespace
}  // namespace tomorig::testing
