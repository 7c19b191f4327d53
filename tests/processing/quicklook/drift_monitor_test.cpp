// Drift alarm against the simulator's truth: the tpiv-thesis cameras, one of them moved by
// 0.5 px in the middle of a run (issue 16: the alarm must fire within 20 sets and name it, and
// stay silent without a move).
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "tomorig/core/error.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/processing/quicklook/drift_monitor.h"
#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/light_sheet.h"
#include "tomorig/simulators/particle_renderer.h"
#include "tomorig/simulators/random.h"
#include "tomorig/simulators/scene.h"
#include "tomorig/simulators/sensor.h"

namespace tomorig::quicklook {
namespace {

using calibration::CameraModel;

// The tpiv-thesis rig: true camera models (the calibration the monitor is given) and a camera
// that moved by `shift` px on its sensor (the model the images are rendered through after the
// move).
struct Rig {
  const sim::CaseDefinition& thesis = sim::find_case("tpiv-thesis");
  std::vector<std::shared_ptr<const CameraModel>> truth;
  std::vector<calibration::ImageSize> sizes;
  calibration::VolumeBounds bounds{thesis.slab.min, thesis.slab.max};

  Rig() {
    for (const sim::SimulatedCameraSpec& c : thesis.cameras) {
      truth.push_back(std::make_shared<calibration::PinholeCamera>(calibration::PinholeCamera::yawed(
          c.yaw_deg, c.focal_length_mm, c.pixel_pitch_um, c.distance_mm, c.width, c.height)));
      sizes.push_back({c.width, c.height});
    }
  }

  std::shared_ptr<const CameraModel> moved(std::size_t camera, Vec2d shift) const {
    calibration::FitReport report;
    return calibration::misaligned_camera(*truth[camera], sizes[camera], bounds, shift, 0.0, report);
  }

  // Particle peaks of set k at `ppp` as a perfect detector with 0.05 px of localisation noise
  // would give them: each particle projected through the camera's `models` entry.
  std::vector<std::vector<Vec2d>> peaks(std::uint64_t k, double ppp,
                                        const std::vector<std::shared_ptr<const CameraModel>>& models) const {
    const auto count = static_cast<std::size_t>(ppp * sizes[0].width * sizes[0].height);
    const auto particles = sim::uniform_particles(thesis.slab, count, sim::derive_seed(77, {k}));
    std::mt19937_64 rng(sim::derive_seed(79, {k}));
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<std::vector<Vec2d>> out(models.size());
    for (std::size_t c = 0; c < models.size(); ++c)
      for (const Vec3d& p : particles) {
        const Vec2d uv = models[c]->project(p);
        if (uv.x >= 0.5 && uv.y >= 0.5 && uv.x < sizes[c].width - 1.5 && uv.y < sizes[c].height - 1.5)
          out[c].push_back({uv.x + noise(rng), uv.y + noise(rng)});
      }
    return out;
  }

  // One exposure of set k at `ppp`, each camera imaged through `models`.
  std::vector<Image> render(std::uint64_t k, double ppp, const std::vector<std::shared_ptr<const CameraModel>>& models) const {
    const auto count = static_cast<std::size_t>(ppp * sizes[0].width * sizes[0].height);
    const auto particles = sim::uniform_particles(thesis.slab, count, sim::derive_seed(77, {k}));
    const sim::LightSheet sheet = sim::LightSheet::for_slab(sim::LightSheetProfile::uniform, thesis.slab);
    sim::ParticleImageOptions image_options;
    image_options.sigma_px = thesis.sigma_px;
    sim::SensorOptions sensor;
    sensor.noise = true;
    sensor.offset_counts = 100;
    std::vector<Image> out;
    for (std::size_t c = 0; c < models.size(); ++c) {
      Image signal = Image::allocate(sizes[c].width, sizes[c].height, SampleType::f32);
      sim::render_particles(*models[c], particles, sheet, image_options, signal);
      out.push_back(sim::digitise(signal, sensor, sim::derive_seed(78, {k, c})));
    }
    return out;
  }
};

DriftOptions named() {
  DriftOptions options;
  options.camera_names = {"cam0", "cam1", "cam2", "cam3"};
  return options;
}

// The acceptance scenario on particle peaks (projections of the simulated particles with
// 0.05 px of noise): the monitor's triangulation, disparity maps, gauge and alarms.
TEST(DriftMonitor, CameraMovedHalfAPixelMidRunIsNamedWithinTwentySets) {
  const Rig rig;
  DriftOptions options = named();
  options.window_sets = 5;
  DriftMonitor monitor(rig.truth, rig.sizes, rig.bounds, options);
  constexpr std::size_t kMoved = 1;
  constexpr int kMoveAt = 4;
  const int last = kMoveAt + options.window_sets;  // the window then holds only moved sets
  std::vector<std::shared_ptr<const CameraModel>> imaging = rig.truth;
  int fired_at = -1;
  for (int k = 0; k <= last; ++k) {
    if (k == kMoveAt) imaging[kMoved] = rig.moved(kMoved, {0.3, 0.4});  // 0.5 px
    const DriftReport& r = monitor.add_peaks(rig.peaks(static_cast<std::uint64_t>(k), 0.03, imaging));
    std::printf("set %d: %zu matches, largest %.3f %.3f %.3f %.3f px, %zu alarms\n", k, r.matches, r.largest_px[0],
                r.largest_px[1], r.largest_px[2], r.largest_px[3], r.alarms.size());
    for (std::size_t c = 0; c < 4; ++c) EXPECT_EQ(r.valid_subvolumes[c], 75) << "set " << k << " camera " << c;
    if (k < kMoveAt) {
      EXPECT_TRUE(r.alarms.empty()) << "set " << k;
      EXPECT_EQ(r.flag, Flag::green) << "set " << k;
      continue;
    }
    for (const DriftAlarm& a : r.alarms) {
      EXPECT_EQ(a.camera, "cam1") << a.message;
      EXPECT_EQ(a.camera_index, 1);
      EXPECT_NE(a.message.find("cam1"), std::string::npos);
      EXPECT_NE(a.message.find("sub-volume"), std::string::npos);
    }
    if (!r.alarms.empty() && fired_at < 0) {
      fired_at = k;
      std::printf("%s\n", r.alarms.front().message.c_str());
    }
    if (fired_at >= 0) {
      EXPECT_EQ(r.flag, Flag::red);
    }
    // The unmoved cameras keep well below the warning.
    for (const std::size_t c : {0, 2, 3}) EXPECT_LT(r.largest_px[c], 0.15) << "set " << k << " camera " << c;
    if (k == last) {
      // Every sub-volume of the moved camera carries the whole move (the disparity is the
      // projection minus the detected peak: the move with the opposite sign).
      for (const SubvolumeDrift& s : r.cameras[kMoved]) {
        EXPECT_NEAR(s.disparity.x, -0.3, 0.1) << s.i << s.j << s.k;
        EXPECT_NEAR(s.disparity.y, -0.4, 0.1) << s.i << s.j << s.k;
      }
      EXPECT_EQ(r.alarms.size(), 75u);
    }
  }
  ASSERT_GE(fired_at, kMoveAt) << "no alarm within 20 sets of the move";
  EXPECT_LT(fired_at - kMoveAt, 20);
}

// The same path from rendered images (shot and read noise, 100 counts black level): particle
// detection included, well-calibrated cameras stay silent.
TEST(DriftMonitor, RenderedImagesOfACalibratedRigRaiseNoAlarm) {
  const Rig rig;
  DriftMonitor monitor(rig.truth, rig.sizes, rig.bounds, named());
  for (std::uint64_t k = 0; k < 3; ++k) {
    const DriftReport& r = monitor.add_set(rig.render(k, 0.05, rig.truth));
    EXPECT_TRUE(r.alarms.empty()) << "set " << k;
    for (std::size_t c = 0; c < 4; ++c) {
      EXPECT_EQ(r.valid_subvolumes[c], 75) << "set " << k << " camera " << c;
      if (k > 0) {
        EXPECT_LT(r.largest_px[c], 0.15) << "set " << k << " camera " << c;
      }
    }
  }
  EXPECT_EQ(monitor.report().sets, 3);
  monitor.reset();
  EXPECT_EQ(monitor.report().sets, 0);
  EXPECT_EQ(monitor.report().matches, 0u);
}

// The "silent over 500 sets" on peaks: long (minutes on a loaded machine), so run by
// hand: test_processing_quicklook --gtest_also_run_disabled_tests --gtest_filter='*Silent*'.
TEST(DriftMonitor, DISABLED_SilentOverFiveHundredSetsWithoutAMove) {
  const Rig rig;
  DriftMonitor monitor(rig.truth, rig.sizes, rig.bounds, named());
  double largest = 0;
  std::size_t alarms = 0;
  for (std::uint64_t k = 0; k < 500; ++k) {
    const DriftReport& r = monitor.add_peaks(rig.peaks(k, 0.03, rig.truth));
    alarms += r.alarms.size();
    if (r.sets >= 3) {
      for (const double l : r.largest_px) largest = std::max(largest, l);
    }
  }
  std::printf("500 sets: %zu alarms, largest sub-volume disparity %.3f px (from the third set on)\n", alarms, largest);
  EXPECT_EQ(alarms, 0u);
}

TEST(DriftMonitor, BadInputIsRefused) {
  const Rig rig;
  EXPECT_THROW(DriftMonitor({rig.truth[0], rig.truth[1]}, {rig.sizes[0], rig.sizes[1]}, rig.bounds), Error);
  EXPECT_THROW(DriftMonitor(rig.truth, {rig.sizes[0]}, rig.bounds), Error);
  EXPECT_THROW(DriftMonitor(rig.truth, rig.sizes, {{0, 0, 0}, {0, 1, 1}}), Error);
  DriftOptions bad;
  bad.warn_px = 2.0;  // beyond the search radius: could never fire
  EXPECT_THROW(DriftMonitor(rig.truth, rig.sizes, rig.bounds, bad), Error);
  DriftMonitor monitor(rig.truth, rig.sizes, rig.bounds);
  std::vector<Image> three(3, Image::allocate(512, 512, SampleType::u16));
  EXPECT_THROW(monitor.add_set(three), Error);
  std::vector<Image> wrong(4, Image::allocate(256, 512, SampleType::u16));
  try {
    monitor.add_set(wrong);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("camera 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::quicklook
