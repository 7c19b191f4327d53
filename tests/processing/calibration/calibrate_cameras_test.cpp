// calibration::calibrate_cameras(): every model on every camera, reported side by side, the
// stored model's calibrations, cross-validation and the automatic choice, judged against the
// known cameras that made the points.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "synthetic_points.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/calibrate_cameras.h"

namespace tomorig::testing {
namespace {

using calibration::CalibrateCamerasOptions;
using calibration::CalibrateCamerasReport;
using calibration::ImageSize;
using calibration::PointCorrespondence;

const std::vector<double> kPlanes{-3, -1.5, 0, 1.5, 3};

struct TwoCameras {
  std::vector<std::vector<PointCorrespondence>> points;
  std::vector<ImageSize> sizes{{calib_test::kImageSize, calib_test::kImageSize},
                               {calib_test::kImageSize, calib_test::kImageSize}};
  std::vector<calib_test::Truth> truth;

  explicit TwoCameras(double radial_k) {
    for (double yaw : {-14.0, 14.0}) {
      calib_test::Truth t{calib_test::thesis_camera(yaw), radial_k};
      points.push_back(calib_test::grid_points(t, kPlanes, 9));
      truth.push_back(t);
    }
  }
};

TEST(CalibrateCameras, FitsEveryModelPerCameraAndStoresTheChosenOne) {
  const TwoCameras rig(0.0);
  CalibrateCamerasOptions options;
  options.models = {"pinhole", "rational2"};
  options.stored = "pinhole";
  const CalibrateCamerasReport report = calibration::calibrate_cameras(rig.points, rig.sizes, options);

  ASSERT_EQ(report.results.size(), 4u);  // 2 cameras x 2 models, camera by camera
  EXPECT_EQ(report.results[0].camera, 0);
  EXPECT_EQ(report.results[0].report.model, "pinhole");
  EXPECT_EQ(report.results[1].report.model, "rational2");
  EXPECT_EQ(report.results[3].camera, 1);
  for (const auto& r : report.results) {
    EXPECT_TRUE(r.error.empty()) << r.error;
    EXPECT_EQ(r.planes.size(), kPlanes.size());
    EXPECT_LT(r.report.forward_rms_px, 1e-3) << "noise-free points of a pinhole camera";
  }
  EXPECT_FALSE(report.stored_failure.has_value());
  EXPECT_EQ(report.failure_message(), "");
  ASSERT_EQ(report.calibrations.size(), 2u);
  EXPECT_EQ(report.calibrations[1].id, 1);
  EXPECT_EQ(report.calibrations[1].report.model, "pinhole");
  // The stored model projects as the camera that made the points, off the planes too.
  for (const Vec3d& w : calib_test::random_points(20, 4.0, -3, 3)) {
    const Vec2d want = rig.truth[1].image_of(w);
    const Vec2d got = report.calibrations[1].model->project(w);
    EXPECT_NEAR(got.x, want.x, 1e-3);
    EXPECT_NEAR(got.y, want.y, 1e-3);
  }
  EXPECT_TRUE(report.poor_fit_warnings().empty());
  EXPECT_TRUE(report.validation.empty()) << "not asked for";
  EXPECT_FALSE(report.offsets.has_value());
}

TEST(CalibrateCameras, ChoosesByLeaveOnePlaneOutErrorAndWarnsOfAPoorStoredFit) {
  const TwoCameras rig(2e-3);  // a lens the pinhole cannot follow (~1.4 px at the corners)
  CalibrateCamerasOptions options;
  options.models = {"pinhole", "rational2"};
  options.choose_model = true;
  std::vector<std::string> notices;
  options.notice = [&](const std::string& text) { notices.push_back(text); };
  const CalibrateCamerasReport report = calibration::calibrate_cameras(rig.points, rig.sizes, options);

  EXPECT_EQ(report.stored, "rational2");
  ASSERT_EQ(report.validation.size(), 4u);  // camera 0: pinhole, rational2; camera 1: the same
  for (const auto& cv : report.validation) {
    EXPECT_TRUE(cv.error.empty()) << cv.error;
    EXPECT_EQ(cv.folds, static_cast<int>(kPlanes.size()));
    EXPECT_EQ(cv.points, static_cast<int>(kPlanes.size()) * 81);
  }
  EXPECT_GT(report.validation[0].rms_px, 0.05) << "the pinhole misses the lens on the planes left out";
  EXPECT_LT(report.validation[1].rms_px, report.validation[0].rms_px / 3);
  EXPECT_LT(report.validation[3].rms_px, report.validation[2].rms_px / 3);
  ASSERT_EQ(notices.size(), 1u);
  EXPECT_NE(notices[0].find("stored rational2"), std::string::npos) << notices[0];
  ASSERT_EQ(report.calibrations.size(), 2u);
  EXPECT_EQ(report.calibrations[0].report.model, "rational2");
  EXPECT_TRUE(report.poor_fit_warnings().empty());
  CalibrateCamerasReport poor;
  calibration::CameraCalibration loose;
  loose.report.model = "pinhole";
  loose.report.forward_rms_px = 2 * calibration::kCalibrationWarnRmsPx;
  poor.calibrations.push_back(std::move(loose));
  EXPECT_EQ(poor.poor_fit_warnings().size(), 1u) << "a fit above the threshold warns";
}

TEST(CalibrateCameras, AStoredModelThatFailsIsReportedNotThrown) {
  TwoCameras rig(0.0);
  // One plane: a pinhole cannot be determined from it (no depth), for camera 1 only.
  std::vector<PointCorrespondence> one_plane;
  for (const auto& p : rig.points[1])
    if (p.world.z == 0) one_plane.push_back(p);
  rig.points[1] = one_plane;
  CalibrateCamerasOptions options;
  options.models = {"rational2", "pinhole"};
  options.stored = "rational2";
  std::vector<std::string> notices;
  options.notice = [&](const std::string& text) { notices.push_back(text); };
  const CalibrateCamerasReport report = calibration::calibrate_cameras(rig.points, rig.sizes, options);

  ASSERT_EQ(report.results.size(), 4u);
  EXPECT_TRUE(report.results[0].error.empty());
  EXPECT_FALSE(report.results[2].error.empty()) << "camera 1's rational2 from one plane";
  ASSERT_TRUE(report.stored_failure.has_value());
  EXPECT_NE(report.failure_message().find("failed for camera 1"), std::string::npos) << report.failure_message();
  EXPECT_EQ(report.calibrations.size(), 1u) << "only camera 0's";
  ASSERT_FALSE(notices.empty());
  EXPECT_EQ(notices[0].rfind("error rational2:", 0), 0u) << notices[0];
}

TEST(CalibrateCameras, RefusesMismatchedInput) {
  const TwoCameras rig(0.0);
  CalibrateCamerasOptions options;
  options.models = {"pinhole"};
  options.stored = "pinhole";
  const std::vector<ImageSize> one_size{rig.sizes[0]};
  EXPECT_THROW(calibration::calibrate_cameras(rig.points, one_size, options), Error);
  options.models.clear();
  EXPECT_THROW(calibration::calibrate_cameras(rig.points, rig.sizes, options), Error);
}

}  // namespace
}  // namespace tomorig::testing
