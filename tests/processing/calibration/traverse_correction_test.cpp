// Traverse-error correction on the reduced calib-thesis case: the recovered per-plane offsets
// match the simulator's stage errors (same zero-mean gauge) and the residuals drop.
#include <chrono>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/fit_camera_model.h"
#include "tomorig/processing/calibration/target_detection.h"
#include "tomorig/processing/calibration/traverse_correction.h"
#include "tomorig/simulators/calibration_target.h"

namespace tomorig::calibration {
namespace {

struct Detected {
  sim::CalibTargetCase c;
  std::vector<std::vector<PointCorrespondence>> points;
  std::vector<ImageSize> sizes;
};

// Rendered and detected once for all tests of this file (rendering dominates their time).
const Detected& reduced_case() {
  static const Detected d = [] {
    sim::CalibTargetOptions o;
    o.reduced = true;
    o.seed = 11;
    Detected out{sim::make_calib_thesis_case(o), {}, {}};
    for (std::size_t cam = 0; cam < out.c.cameras.size(); ++cam) {
      out.sizes.push_back({out.c.cameras[cam].width, out.c.cameras[cam].height});
      out.points.emplace_back();
      for (std::size_t k = 0; k < out.c.planes.size(); ++k) {
        const TargetDetection t =
            detect_chessboard(sim::render_target_view(out.c, cam, k), out.c.board, out.c.planes[k].z_nominal_mm, "test");
        out.points.back().insert(out.points.back().end(), t.points.begin(), t.points.end());
      }
    }
    return out;
  }();
  return d;
}

// The simulator's true offsets in the correction's gauge.
std::vector<Vec3d> gauged_truth(const sim::CalibTargetCase& c) {
  std::vector<Vec3d> t;
  std::vector<double> z;
  for (const auto& p : c.planes) t.push_back(p.offset_mm), z.push_back(p.z_nominal_mm);
  remove_gauge(t, z);
  return t;
}

TEST(TraverseCorrection, RecoversPlaneOffsetsWithinOneMicrometre) {
  const Detected& d = reduced_case();
  TraverseCorrectionOptions o;
  o.final_model = "rational2";
  const auto t0 = std::chrono::steady_clock::now();
  const TraverseCorrectionResult r = correct_traverse(d.points, d.sizes, o);
  std::printf("correction: %d cycles, converged %d, %.2f s\n", r.cycles, int(r.converged),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  EXPECT_TRUE(r.converged);
  const std::vector<Vec3d> truth = gauged_truth(d.c);
  ASSERT_EQ(r.offsets_mm.size(), truth.size());
  double largest_truth = 0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_EQ(r.plane_z_mm[k], d.c.planes[k].z_nominal_mm);
    const Vec3d e = r.offsets_mm[k] - truth[k];
    std::printf("plane %zu: truth (%.2f %.2f %.2f) um, estimate (%.2f %.2f %.2f) um\n", k, truth[k].x * 1e3,
                truth[k].y * 1e3, truth[k].z * 1e3, r.offsets_mm[k].x * 1e3, r.offsets_mm[k].y * 1e3,
                r.offsets_mm[k].z * 1e3);
    EXPECT_LT(e.norm() * 1e3, 1.0) << "plane " << k;
    largest_truth = std::max(largest_truth, truth[k].norm() * 1e3);
  }
  EXPECT_GT(largest_truth, 5.0);  // the case really has stage errors to find
  EXPECT_EQ(r.per_camera_offsets_mm.size(), d.points.size());
  ASSERT_EQ(r.models.size(), d.points.size());
  // Residuals with correction beat those without, camera by camera.
  for (std::size_t cam = 0; cam < d.points.size(); ++cam) {
    FitOptions fo;
    FitReport plain;
    fit_camera_model("rational2", d.points[cam], d.sizes[cam], fo, plain);
    std::printf("camera %zu: rational2 %.4f px without, %.4f px with correction\n", cam + 1, plain.forward_mean_px,
                r.reports[cam].forward_mean_px);
    EXPECT_LT(r.reports[cam].forward_mean_px, 0.8 * plain.forward_mean_px) << "camera " << cam + 1;
  }
}

TEST(TraverseCorrection, GaugeRemovesMeanAndXZTrendsButKeepsTheRest) {
  const std::vector<double> z{-1, 0, 1};
  // A pure gauge: shift + x shear + z scale -> nothing left.
  std::vector<Vec3d> g{{0.1 - 0.02, 0.3, 0.2 - 0.05}, {0.1, 0.3, 0.2}, {0.1 + 0.02, 0.3, 0.2 + 0.05}};
  remove_gauge(g, z);
  for (const Vec3d& v : g) EXPECT_NEAR(v.norm(), 0.0, 1e-15);
  // A y trend and curvature are physical: they stay.
  std::vector<Vec3d> h{{0.01, -0.004, 0.01}, {-0.02, 0, -0.02}, {0.01, 0.004, 0.01}};
  const std::vector<Vec3d> before = h;
  remove_gauge(h, z);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR((h[k] - before[k]).norm(), 0.0, 1e-15);
}

TEST(TraverseCorrection, ApplyPlaneOffsetsShiftsEachPlane) {
  const std::vector<PointCorrespondence> pts{{{1, 2, -1.5}, {10, 20}}, {{3, 4, 0}, {30, 40}}};
  const std::vector<double> z{-1.5, 0};
  const std::vector<Vec3d> off{{0.001, 0.002, 0.003}, {-0.001, 0, 0.01}};
  const auto out = apply_plane_offsets(pts, z, off);
  EXPECT_DOUBLE_EQ(out[0].world.x, 1.001);
  EXPECT_DOUBLE_EQ(out[0].world.z, -1.497);
  EXPECT_DOUBLE_EQ(out[1].world.z, 0.01);
  EXPECT_EQ(out[1].pixel.y, 40);
  const std::vector<double> other{-3};
  const std::vector<Vec3d> one{{0, 0, 0}};
  EXPECT_THROW(apply_plane_offsets(pts, other, one), Error);
}

TEST(TraverseCorrection, RefusesOneCameraOrOnePlane) {
  const Detected& d = reduced_case();
  TraverseCorrectionOptions o;
  EXPECT_THROW(correct_traverse(std::span(d.points).first(1), std::span(d.sizes).first(1), o), Error);
  std::vector<std::vector<PointCorrespondence>> one_plane(2);
  for (std::size_t cam = 0; cam < 2; ++cam)
    for (const auto& p : d.points[cam])
      if (p.world.z == d.c.planes[3].z_nominal_mm) one_plane[cam].push_back(p);
  EXPECT_THROW(correct_traverse(one_plane, std::span(d.sizes).first(2), o), Error);
  o.final_model = "spline";
  try {
    correct_traverse(d.points, d.sizes, o);
    FAIL() << "an unknown model must be refused";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("spline"), std::string::npos);
  }
}

}  // namespace
}  // namespace tomorig::calibration

namespace tomorig::calibration {
namespace {
// The full-size case takes minutes, so it is disabled; `tomorig bench calib` gives the same
// figures as JSON. Run it with --gtest_also_run_disabled_tests --gtest_filter='*FullSizeLook'.
TEST(TraverseCorrection, DISABLED_FullSizeLook) {
  sim::CalibTargetOptions o;
  o.seed = 1;
  const sim::CalibTargetCase c = sim::make_calib_thesis_case(o);
  std::vector<std::vector<PointCorrespondence>> points(c.cameras.size());
  std::vector<ImageSize> sizes;
  for (std::size_t cam = 0; cam < c.cameras.size(); ++cam) {
    sizes.push_back({c.cameras[cam].width, c.cameras[cam].height});
    for (std::size_t k = 0; k < c.planes.size(); ++k) {
      const TargetDetection t = detect_chessboard(sim::render_target_view(c, cam, k), c.board, c.planes[k].z_nominal_mm, "full");
      points[cam].insert(points[cam].end(), t.points.begin(), t.points.end());
    }
  }
  for (const char* model : {"pinhole", "rational2"}) {
    TraverseCorrectionOptions opt;
    opt.final_model = model;
    const TraverseCorrectionResult r = correct_traverse(points, sizes, opt);
    for (std::size_t cam = 0; cam < points.size(); ++cam) {
      FitOptions fo;
      FitReport plain;
      fit_camera_model(model, points[cam], sizes[cam], fo, plain);
      std::printf("%s camera %zu: %.4f px / %.3f um without, %.4f px / %.3f um with (%d cycles)\n", model, cam + 1,
                  plain.forward_mean_px, plain.reverse_mean_um, r.reports[cam].forward_mean_px,
                  r.reports[cam].reverse_mean_um, r.cycles);
    }
  }
}
}  // namespace
}  // namespace tomorig::calibration
