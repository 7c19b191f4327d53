// Dot-grid detection and model fits on the real 4-camera sample of
// ../shared/data/fluidimage-tomopiv (white dots, 3 mm grid, planes z = -6 ... 6 mm). Nothing
// there is ground truth; the test asks for what a working detector must give: the origin on
// every image, a plausible number of dots (the view holds 9 x 9), +x to the right, and camera
// models that fit the detected points to well under a pixel.
#include <gtest/gtest.h>

#include "real_data.h"

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/storage/image_file.h"

namespace {

namespace fs = std::filesystem;
using tomorig::calibration::PointCorrespondence;

fs::path sample_dir() {
  if (const char* env = std::getenv("TOMORIG_FLUIDIMAGE_DIR")) return env;
  // tests/processing/calibration/ -> the project root -> ../shared/data
  return fs::path(__FILE__).parent_path().parent_path().parent_path().parent_path().parent_path() / "shared" / "data" /
         "fluidimage-tomopiv";
}

TEST(DotGridFluidimage, EveryCameraAndPlaneDetectsAndFits) {
  const fs::path root = sample_dir() / "calibration";
  TOMORIG_NEED_REAL_DATA(root / "cam0" / "0mm_cam0.tif");
  tomorig::calibration::DotGridSpec spec;
  spec.spacing_mm = 3;
  // z points towards the cameras on this rig (the target's image grows with z), so a
  // right-handed frame with x to the right has y up; pinhole refuses a mirrored frame.
  spec.y_down = false;
  for (int cam = 0; cam < 4; ++cam) {
    std::vector<PointCorrespondence> points;
    for (const int z : {-6, -3, 0, 3, 6}) {
      const std::string what = fmt::format("camera {}, plane z = {} mm", cam, z);
      const auto image = tomorig::storage::read_image(root / fmt::format("cam{}", cam) / fmt::format("{}mm_cam{}.tif", z, cam));
      const auto d = tomorig::calibration::detect_dot_grid(image, spec, z, what);
      const PointCorrespondence* origin = nullptr;
      const PointCorrespondence* right = nullptr;
      for (const auto& p : d.points) {
        if (p.world.x == 0 && p.world.y == 0) origin = &p;
        if (p.world.x == 3 && p.world.y == 0) right = &p;
      }
      ASSERT_NE(origin, nullptr) << what;
      ASSERT_NE(right, nullptr) << what;
      EXPECT_GT(right->pixel.x, origin->pixel.x + 40) << what << ": +x must point right in the image";
      // fluidimage's own calibration (camN.h5: C = (250, 250), translate ~ 0 at z = 0) puts the
      // origin at the image point (250, 250) on the plane z = 0 of every camera.
      if (z == 0) {
        EXPECT_NEAR(origin->pixel.x, 250, 2) << what;
        EXPECT_NEAR(origin->pixel.y, 250, 2) << what;
      }
      EXPECT_GE(d.points.size(), 60u) << what;
      EXPECT_LE(d.points.size(), 100u) << what;
      points.insert(points.end(), d.points.begin(), d.points.end());
    }
    for (const std::string model : {"pinhole", "soloff3"}) {
      tomorig::calibration::FitOptions options;
      options.camera = fmt::format("camera {}", cam);
      tomorig::calibration::FitReport report;
      tomorig::calibration::fit_camera_model(model, points, {504, 500}, options, report);
      // The sample's images fit a pinhole camera to ~0.002 px; 0.05 px leaves a wide margin.
      EXPECT_LT(report.forward_mean_px, 0.05) << report.brief();
    }
  }
}

}  // namespace
