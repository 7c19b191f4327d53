// Volume self-calibration against the simulator's ground truth: the tpiv-thesis cameras and
// particles, one camera misaligned by a 1.0 px shift and a 0.2 deg rotation (issue 3).
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/self_calibration.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::calibration {
namespace {

struct Scene {
  std::vector<std::shared_ptr<const CameraModel>> truth;
  std::vector<ImageSize> sizes;
  std::vector<ParticleSnapshot> snapshots;
  std::vector<Vec3d> particles;  // true positions of every snapshot's particles
  VolumeBounds bounds;
};

// One set (exposures A and B) of the tpiv-thesis case at `ppp`.
Scene simulate(double ppp, std::uint64_t seed) {
  sim::SimulationOptions options;
  options.ppp = ppp;
  options.seed = seed;
  const sim::SimulatedRig rig(options);
  Scene s;
  for (const sim::SimulatedCamera& c : rig.cameras()) {
    s.truth.push_back(std::make_shared<PinholeCamera>(c.model));
    s.sizes.push_back({c.spec.width, c.spec.height});
  }
  const sim::SimulatedSet set = rig.render_set(0);
  for (const Exposure e : {Exposure::A, Exposure::B}) {
    ParticleSnapshot snapshot;
    for (const CameraFrames& c : set.frames.cameras) snapshot.images.push_back(c[e].image);
    s.snapshots.push_back(std::move(snapshot));
  }
  s.particles = set.particles_a;
  s.particles.insert(s.particles.end(), set.particles_b.begin(), set.particles_b.end());
  s.bounds = {rig.case_definition().slab.min, rig.case_definition().slab.max};
  return s;
}

const Scene& dense_scene() {
  static const Scene scene = simulate(0.05, 11);
  return scene;
}

TEST(SelfCalibration, MisalignedCameraIsCorrectedBelowATenthPixelAndMatchesTheTruth) {
  const Scene& s = dense_scene();
  constexpr std::size_t kMoved = 1;
  FitReport report;
  std::vector<std::shared_ptr<const CameraModel>> models = s.truth;
  models[kMoved] = misaligned_camera(*s.truth[kMoved], s.sizes[kMoved], s.bounds, {0.6, 0.8}, 0.2, report);
  // The misalignment is real: about 1 px on average over the particles.
  ASSERT_GT(projection_difference(*models[kMoved], *s.truth[kMoved], s.particles).mean_px, 0.9);

  const SelfCalibrationResult r = self_calibrate(models, s.sizes, s.snapshots, s.bounds, {});
  EXPECT_TRUE(r.converged);
  EXPECT_GE(r.corrections, 1);
  EXPECT_GT(r.before().cameras[kMoved].volume.mean_px, 0.4);
  EXPECT_LT(r.after().cameras[kMoved].volume.mean_px, 0.1);
  EXPECT_LT(r.after().cameras[kMoved].z_min_layer.mean_px, 0.1);
  EXPECT_LT(r.after().cameras[kMoved].z_max_layer.mean_px, 0.1);
  // The honest figure: the corrected models project the true particles where the true
  // cameras do, the moved camera included (the gauge keeps the world frame in place).
  for (std::size_t c = 0; c < models.size(); ++c) {
    const ProjectionDifference d = projection_difference(*r.models[c], *s.truth[c], s.particles);
    EXPECT_LT(d.mean_px, 0.1) << "camera " << c;
    EXPECT_LT(d.max_px, 0.3) << "camera " << c;
  }
}

TEST(SelfCalibration, WellCalibratedCamerasStayPut) {
  const Scene& s = dense_scene();
  const SelfCalibrationResult r = self_calibrate(s.truth, s.sizes, s.snapshots, s.bounds, {});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.corrections, 0);
  ASSERT_EQ(r.passes.size(), 1u);
  for (std::size_t c = 0; c < s.truth.size(); ++c) {
    EXPECT_EQ(r.models[c], s.truth[c]) << "camera " << c;
    EXPECT_LT(r.after().cameras[c].volume.mean_px, 0.05) << "camera " << c;
    EXPECT_GE(r.after().cameras[c].volume.subvolumes, 60) << "camera " << c;
  }
}

TEST(SelfCalibration, TooFewParticlesIsAClearError) {
  const Scene s = simulate(0.0005, 3);
  try {
    self_calibrate(s.truth, s.sizes, s.snapshots, s.bounds, {});
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("too few particles"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("camera 0"), std::string::npos) << e.what();
  }
}

TEST(SelfCalibration, NonConvergenceNamesTheCamera) {
  const Scene& s = dense_scene();
  FitReport report;
  std::vector<std::shared_ptr<const CameraModel>> models = s.truth;
  models[2] = misaligned_camera(*s.truth[2], s.sizes[2], s.bounds, {0.0, 1.0}, 0.0, report);
  SelfCalibrationOptions options;
  options.max_iterations = 0;  // measure only: the misalignment stays
  options.camera_names = {"cam0", "cam1", "cam2", "cam3"};
  try {
    self_calibrate(models, s.sizes, s.snapshots, s.bounds, options);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::runtime);
    EXPECT_NE(std::string(e.what()).find("cam2"), std::string::npos) << e.what();
  }
}

TEST(SelfCalibration, MismatchedImagesAreBadInput) {
  const Scene& s = dense_scene();
  std::vector<ImageSize> sizes = s.sizes;
  sizes[3] = {256, 256};
  EXPECT_THROW(self_calibrate(s.truth, sizes, s.snapshots, s.bounds, {}), Error);
  EXPECT_THROW(self_calibrate(s.truth, s.sizes, {}, s.bounds, {}), Error);
  SelfCalibrationOptions bad;
  bad.subvolumes_z = 0;
  EXPECT_THROW(self_calibrate(s.truth, s.sizes, s.snapshots, s.bounds, bad), Error);
}

}  // namespace
}  // namespace tomorig::calibration
