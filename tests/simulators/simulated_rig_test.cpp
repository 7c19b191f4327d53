// The tpiv-thesis rig end to end: particle counts, truth, motion, images, determinism, errors.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/simulated_rig.h"

namespace {

using tomorig::Vec2d;
using tomorig::Vec3d;
using tomorig::sim::SimulatedRig;
using tomorig::sim::SimulationOptions;

constexpr double kPi = 3.14159265358979323846;
const double kYaws[] = {-42.0, -14.0, 14.0, 42.0};

SimulationOptions options(double ppp, std::uint64_t seed = 1) {
  SimulationOptions o;
  o.ppp = ppp;
  o.seed = seed;
  return o;
}

// Independent Eq. 3.13 in mm at world X (tpiv-thesis grid; see flow_test.cpp).
Vec3d eq_3_13_mm(const Vec3d& X) {
  const double x = X.x / 0.0195 + 255.5, z = X.z / 0.0195 + 79.5;
  const double w = 2 * kPi / 256, A = 5 * 0.0195;
  return {A * std::sin(w * x) * std::cos(w * z), -A * std::sin(w * x) * std::sin(w * z),
          -A * std::cos(w * x) * std::sin(w * z)};
}

// Independent pinhole projection for the thesis camera at `yaw` (Eq. 3.11, 3.12).
Vec2d project(double yaw, const Vec3d& X) {
  const double phi = yaw * kPi / 180, f = 100.0 / 0.0074;
  const double xc = std::cos(phi) * X.x - std::sin(phi) * X.z, zc = std::sin(phi) * X.x + std::cos(phi) * X.z + 263.16;
  return {f * xc / zc + 255.5, f * X.y / zc + 255.5};
}

bool same_images(const tomorig::FrameSet& a, const tomorig::FrameSet& b) {
  if (a.cameras.size() != b.cameras.size()) return false;
  for (std::size_t c = 0; c < a.cameras.size(); ++c)
    if (!a.cameras[c].a.image.same_pixels(b.cameras[c].a.image) ||
        !a.cameras[c].b.image.same_pixels(b.cameras[c].b.image))
      return false;
  return true;
}

TEST(SimulatedRig, ParticleCountIsPppTimesPixels) {
  for (double ppp : {0.01, 0.05, 0.1}) {
    const SimulatedRig rig(options(ppp));
    EXPECT_EQ(rig.particles_per_set(), static_cast<std::size_t>(std::llround(ppp * 512 * 512)));
  }
  const auto set = SimulatedRig(options(0.01)).render_set(0);
  EXPECT_EQ(set.particles_a.size(), 2621u);
  EXPECT_EQ(set.particles_b.size(), 2621u);
}

TEST(SimulatedRig, DisplacementsFollowEquation313AndMidpointsLieInTheSlab) {
  const SimulatedRig rig(options(0.02, 3));
  const auto set = rig.render_set(1);
  ASSERT_EQ(set.particles_a.size(), set.particles_b.size());
  for (std::size_t n = 0; n < set.particles_a.size(); ++n) {
    const Vec3d a = set.particles_a[n], b = set.particles_b[n];
    const Vec3d mid = (a + b) * 0.5, d = b - a, want = eq_3_13_mm(mid);
    ASSERT_LE(std::abs(mid.x), 5.0 + 1e-12);
    ASSERT_LE(std::abs(mid.y), 5.0 + 1e-12);
    ASSERT_LE(std::abs(mid.z), 1.5 + 1e-12);
    ASSERT_NEAR(d.x, want.x, 1e-12);
    ASSERT_NEAR(d.y, want.y, 1e-12);
    ASSERT_NEAR(d.z, want.z, 1e-12);
  }
  // The midpoints are the seeded field of this set.
  const auto mid = rig.particle_midpoints(1);
  EXPECT_NEAR((set.particles_a[7].x + set.particles_b[7].x) / 2, mid[7].x, 1e-15);
}

TEST(SimulatedRig, TruthCamerasAreTheThesisGeometry) {
  const SimulatedRig rig(options(0.01));
  ASSERT_EQ(rig.cameras().size(), 4u);
  for (std::size_t c = 0; c < 4; ++c) {
    const auto& p = rig.cameras()[c].model.parameters();
    const double phi = kYaws[c] * kPi / 180;
    EXPECT_EQ(rig.cameras()[c].spec.id, "cam" + std::to_string(c));
    EXPECT_NEAR(p.R[0], std::cos(phi), 1e-15);
    EXPECT_NEAR(p.R[2], -std::sin(phi), 1e-15);
    EXPECT_NEAR(p.R[6], std::sin(phi), 1e-15);
    EXPECT_NEAR(p.fx, 100.0 / 0.0074, 1e-9);
    EXPECT_EQ(p.t.z, 263.16);
  }
  EXPECT_EQ(rig.flow().name(), "taylor-green");
}

TEST(SimulatedRig, RenderedParticleCentroidIsItsProjection) {
  const SimulatedRig rig(options(0.01));
  const Vec3d points[] = {{0, 0, 0}, {1.234, -2.5, 0.7}, {-3.3, 4.1, -1.2}};
  for (std::size_t c = 0; c < 4; ++c)
    for (const Vec3d& X : points) {
      const tomorig::Image img = rig.render_signal(c, {&X, 1});
      const Vec2d want = project(kYaws[c], X);
      double s = 0, sx = 0, sy = 0;
      for (int y = static_cast<int>(want.y) - 6; y <= static_cast<int>(want.y) + 6; ++y)
        for (int x = static_cast<int>(want.x) - 6; x <= static_cast<int>(want.x) + 6; ++x) {
          const double v = img.value(x, y);
          s += v;
          sx += v * x;
          sy += v * y;
        }
      EXPECT_NEAR(sx / s, want.x, 0.01);
      EXPECT_NEAR(sy / s, want.y, 0.01);
      EXPECT_NEAR(s / (1000.0 * 2 * kPi * 0.75 * 0.75), 1.0, 1e-4);
    }
}

TEST(SimulatedRig, FrameSetLayoutAndTimestamps) {
  SimulationOptions o = options(0.01);
  o.rate_hz = 4.0;
  o.dt_ns = 50'000;
  const auto set = SimulatedRig(o).render_set(3);
  const auto& f = set.frames;
  EXPECT_EQ(f.set_index, 3u);
  EXPECT_EQ(f.trigger_index, 3u);
  EXPECT_EQ(f.trigger_timestamp_ns, 750'000'000);
  EXPECT_EQ(f.dt_ns, 50'000);
  ASSERT_EQ(f.cameras.size(), 4u);
  EXPECT_TRUE(f.complete());
  for (const auto& cam : f.cameras) {
    EXPECT_EQ(cam.a.image.width(), 512);
    EXPECT_EQ(cam.a.image.height(), 512);
    EXPECT_EQ(cam.b.image.type(), tomorig::SampleType::u16);
    EXPECT_EQ(cam.a.timestamp_ns, 750'000'000);
    EXPECT_EQ(cam.b.timestamp_ns, 750'050'000);
    EXPECT_FALSE(cam.a.image.same_pixels(cam.b.image));  // the particles moved
  }
}

TEST(SimulatedRig, SameSeedSameImagesOtherSeedOrSetOtherImages) {
  const auto a = SimulatedRig(options(0.01, 5)).render_set(0);
  const auto b = SimulatedRig(options(0.01, 5)).render_set(0);
  const auto c = SimulatedRig(options(0.01, 6)).render_set(0);
  const auto d = SimulatedRig(options(0.01, 5)).render_set(1);
  EXPECT_TRUE(same_images(a.frames, b.frames));
  EXPECT_FALSE(same_images(a.frames, c.frames));
  EXPECT_FALSE(same_images(a.frames, d.frames));
  EXPECT_NE(a.particles_a[0].x, d.particles_a[0].x);
}

TEST(SimulatedRig, OneThreadAndManyThreadsGiveIdenticalImages) {
  SimulationOptions o = options(0.05, 9);
  o.noise = true;
  o.threads = 1;
  const auto one = SimulatedRig(o).render_set(0);
  o.threads = 4;
  const auto many = SimulatedRig(o).render_set(0);
  EXPECT_TRUE(same_images(one.frames, many.frames));
}

TEST(SimulatedRig, TwelveBitCamerasSaturateAt4095) {
  SimulationOptions o = options(0.01);
  o.cameras = tomorig::sim::find_case("tpiv-thesis").cameras;
  for (auto& c : o.cameras) c.pixel_format = tomorig::PixelFormat::Mono12;
  o.peak_counts = 20000;
  const auto set = SimulatedRig(o).render_set(0);
  const tomorig::Image& img = set.frames.cameras[0].a.image;
  int max = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) max = std::max(max, static_cast<int>(img.at<std::uint16_t>(x, y)));
  EXPECT_EQ(max, 4095);
}

TEST(SimulatedRig, CamerasFromSpecsReplaceTheCaseCameras) {
  SimulationOptions o = options(0.01);
  tomorig::sim::SimulatedCameraSpec spec;
  spec.id = "left";
  spec.yaw_deg = -30;
  spec.width = 256;
  spec.height = 128;
  o.cameras = {spec};
  const SimulatedRig rig(o);
  ASSERT_EQ(rig.cameras().size(), 1u);
  EXPECT_EQ(rig.particles_per_set(), static_cast<std::size_t>(std::llround(0.01 * 256 * 128)));
  const auto set = rig.render_set(0);
  EXPECT_EQ(set.frames.cameras[0].camera_id, "left");
  EXPECT_EQ(set.frames.cameras[0].a.image.width(), 256);
}

void expect_bad_input(const SimulationOptions& o, const std::string& needle) {
  try {
    SimulatedRig rig(o);
    FAIL() << "accepted: " << needle;
  } catch (const tomorig::Error& e) {
    EXPECT_EQ(e.kind(), tomorig::ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(SimulatedRig, RejectsUnknownCaseAndPppOutOfRange) {
  SimulationOptions o = options(0.05);
  o.case_name = "nope";
  expect_bad_input(o, "nope");
  expect_bad_input(o, "tpiv-thesis");  // the message lists what is available
  for (double ppp : {0.0, -0.1, 1.5, std::nan("")}) expect_bad_input(options(ppp), "ppp");
  EXPECT_NO_THROW(SimulatedRig(options(1.0)));
  SimulationOptions mono8 = options(0.05);
  mono8.cameras = tomorig::sim::find_case("tpiv-thesis").cameras;
  mono8.cameras[2].pixel_format = tomorig::PixelFormat::Mono8;
  expect_bad_input(mono8, "Mono8");
}

}  // namespace
