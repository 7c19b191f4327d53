// The spray quick-look (issue 20) on the spray-thesis simulator's frames, against its truth:
// the LED pulse energies it rendered (A/B ratio, a 20 % drop flagged red), the droplet shadows
// deep enough to pass the detection threshold, and the run-history alarm.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/json.h"
#include "tomorig/processing/quicklook/shadow_look.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::quicklook {
namespace {

sim::SprayCase reduced_case(double pulse_b_energy, std::uint64_t seed) {
  sim::SprayOptions o;
  o.reduced = true;
  o.seed = seed;
  o.pulse_b_energy = pulse_b_energy;
  return sim::make_spray_thesis_case(o);
}

// A copy of `image` with every sample times `factor`: the same frame under a weaker pulse.
Image scaled(const Image& image, double factor) {
  Image out = image.clone();
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      out.row<std::uint16_t>(y)[x] = static_cast<std::uint16_t>(std::lround(out.row<std::uint16_t>(y)[x] * factor));
  return out;
}

TEST(ShadowLook, EnergyRatioFollowsTheRenderedPulsesAndATwentyPercentDropIsRed) {
  for (const double drop : {1.0, 0.8}) {
    const sim::SprayCase c = reduced_case(drop, 21);
    const sim::SpraySet s = sim::render_spray_set(c, 0);
    for (std::size_t ci = 0; ci < c.cameras.size(); ++ci) {
      ShadowLook look;
      ShadowCameraLook r;
      look.analyse(s.frames.cameras[ci].a.image, s.frames.cameras[ci].b.image, r);
      const double truth = s.pulse_energy_b[ci] / s.pulse_energy_a[ci];
      EXPECT_NEAR(r.energy_ratio.value, truth, 0.01 * truth) << c.cameras[ci].id;
      // The bright field is 5 % of full scale with a 15 % corner fall-off: the median tile
      // lies between the centre's level and the corner's.
      const double centre = 0.05 * 65535.0 * s.pulse_energy_a[ci];
      EXPECT_LT(r.a.bright_level, centre * 1.005);
      EXPECT_GT(r.a.bright_level, centre * 0.85);
      // The flat-fielded noise is the camera's sigma (0.010 outer, 0.006 inner views).
      EXPECT_NEAR(r.a.noise, c.cameras[ci].noise_sigma, 0.25 * c.cameras[ci].noise_sigma);
      if (drop == 1.0) {
        EXPECT_EQ(r.energy_ratio.flag, Flag::green);
        EXPECT_TRUE(r.alarms.empty());
      } else {
        EXPECT_EQ(r.energy_ratio.flag, Flag::red);
        EXPECT_EQ(r.overall(), Flag::red);
        ASSERT_FALSE(r.alarms.empty());
        // "LED pulse B 20 % below pulse A": the rendered drop, pulse-to-pulse jitter included.
        int percent = -1;
        ASSERT_EQ(std::sscanf(r.alarms[0].c_str(), "LED pulse B %d %% below pulse A", &percent), 1) << r.alarms[0];
        EXPECT_NEAR(percent, 100.0 * (1.0 - truth), 0.51) << r.alarms[0];
      }
    }
  }
}

TEST(ShadowLook, ShadowCountMatchesTheDropletsDeepEnoughToBeSeen) {
  const sim::SprayCase c = reduced_case(1.0, 5);
  const sim::SpraySet s = sim::render_spray_set(c, 1);
  for (std::size_t ci = 0; ci < c.cameras.size(); ++ci) {
    ShadowLook look;
    ShadowFrame f;
    look.analyse(s.frames.cameras[ci].a.image, f);
    // Droplets whose own noise-free shadow reaches well past the detection threshold (1 - 4
    // sigma); overlapping shadows merge into one (the jet's plume is dense), so the count
    // falls short of it by up to a quarter.
    const double threshold = 1.0 - look.options().shadow_sigmas * c.cameras[ci].noise_sigma;
    int deep = 0, in_view = 0;
    for (const sim::Droplet& d : s.droplets) {
      in_view += d.min_intensity[ci] < 1.0;
      deep += d.min_intensity[ci] < threshold - 2 * c.cameras[ci].noise_sigma;
    }
    ASSERT_GT(deep, 50);
    EXPECT_EQ(f.binning, 1) << "the reduced case is measured as it is";
    EXPECT_GE(f.shadows.value, 0.75 * deep) << c.cameras[ci].id << " in view " << in_view;
    EXPECT_LE(f.shadows.value, static_cast<double>(in_view)) << c.cameras[ci].id;
    EXPECT_GT(f.shadow_coverage.value, 0.0);
    EXPECT_EQ(f.shadow_coverage.flag, Flag::green) << "a sparse spray";
    // The deepest shadow: a large droplet's, near the transmission floor of its disc.
    double deepest = 1.0;
    for (const sim::Droplet& d : s.droplets) deepest = std::min(deepest, d.min_intensity[ci]);
    EXPECT_NEAR(f.min_intensity.value, deepest, 0.1);
    EXPECT_GT(f.spray_tile_fraction, 0.0);
  }
}

TEST(ShadowLook, ALedLosingTwentyPercentDuringTheRunIsFlaggedAgainstItsStart) {
  const sim::SprayCase c = reduced_case(1.0, 9);
  ShadowLookOptions options;
  options.reference_sets = 2;
  ShadowLook look(options);
  ShadowCameraLook r;
  for (std::uint64_t k = 0; k < 2; ++k) {
    const sim::SpraySet s = sim::render_spray_set(c, k);
    look.analyse(s.frames.cameras[0].a.image, s.frames.cameras[0].b.image, r);
    EXPECT_EQ(r.reference_ready, k == 1) << k;
  }
  EXPECT_EQ(r.history_a.flag, Flag::green);
  const sim::SpraySet s = sim::render_spray_set(c, 0);
  // The first set again with both pulses 20 % weaker: their ratio is fine, the history is not.
  look.analyse(scaled(s.frames.cameras[0].a.image, 0.8), scaled(s.frames.cameras[0].b.image, 0.8), r);
  EXPECT_EQ(r.energy_ratio.flag, Flag::green);
  EXPECT_EQ(r.history_a.flag, Flag::red);
  EXPECT_EQ(r.history_b.flag, Flag::red);
  ASSERT_EQ(r.alarms.size(), 2u);
  EXPECT_NE(r.alarms[0].find("LED pulse A 20 % below the run's start"), std::string::npos) << r.alarms[0];
  const nlohmann::json j = r;
  EXPECT_EQ(j.at("flag"), "red");
  EXPECT_EQ(j.at("history").at("a").at("flag"), "red");
  EXPECT_TRUE(j.at("a").at("shadows").at("count").is_number());
  EXPECT_EQ(j.at("led_energy_alarms").size(), 2u);
}

// The full-size case (2560 x 2160 px of 6.5 um) is binned 4 x 4 to the reduced case's 26 um
// pixel: judged against the truth of the same droplets rendered at that pixel (the reduced case,
// same seed and droplet count), with the working image's noise (a quarter of the pixel's).
TEST(ShadowLook, AFullSizeFrameIsMeasuredAtTheReducedPixelAgainstItsTruth) {
  sim::SprayOptions o;
  o.seed = 5;
  o.droplets = 800;
  o.pulse_b_energy = 0.8;
  const sim::SprayCase full = sim::make_spray_thesis_case(o);
  o.reduced = true;
  const sim::SprayCase reduced = sim::make_spray_thesis_case(o);
  const sim::SpraySet s = sim::render_spray_set(full, 1);
  const std::vector<sim::Droplet> truth = sim::render_spray_set(reduced, 1).droplets;
  ASSERT_EQ(truth.size(), s.droplets.size());
  for (std::size_t ci = 0; ci < full.cameras.size(); ++ci) {
    ShadowLook look;
    ShadowCameraLook r;
    look.analyse(s.frames.cameras[ci].a.image, s.frames.cameras[ci].b.image, r);
    const ShadowFrame& f = r.a;
    ASSERT_EQ(f.binning, 4) << "2560 x 2160 is binned to 640 x 540 without being asked";
    EXPECT_EQ(f.width, 2560);
    EXPECT_EQ(f.coverage_map.tile_px * f.coverage_map.tiles_x, 2560) << "maps are in frame pixels";
    const double sigma = full.cameras[ci].noise_sigma;
    const double truth_ratio = s.pulse_energy_b[ci] / s.pulse_energy_a[ci];
    EXPECT_NEAR(r.energy_ratio.value, truth_ratio, 0.01 * truth_ratio) << full.cameras[ci].id;
    EXPECT_EQ(r.energy_ratio.flag, Flag::red);
    EXPECT_NEAR(f.noise, sigma, 0.25 * sigma) << "the frame pixel's noise";
    // Binning 16 px averages the sensor's white noise to a quarter, and noise alone makes no
    // shadows on a bright field without spray (its border tiles included, where the flat field
    // is extrapolated).
    ShadowFrame bright;
    look.analyse(sim::render_bright_field(full, ci, 0), bright);
    EXPECT_NEAR(bright.working_noise, sigma / 4, 0.25 * sigma / 4) << full.cameras[ci].id;
    EXPECT_NEAR(bright.noise, sigma, 0.25 * sigma);
    EXPECT_LE(bright.shadows.value, 2) << full.cameras[ci].id;
    EXPECT_NEAR(f.working_noise, sigma / 4, 0.25 * sigma / 4) << full.cameras[ci].id;
    // Droplets whose noise-free shadow at the working pixel passes the look's threshold by 2 of
    // its sigmas, as for the reduced case.
    int deep = 0, in_view = 0;
    double deepest = 1.0;
    for (const sim::Droplet& d : truth) {
      in_view += d.min_intensity[ci] < 1.0;
      deep += d.min_intensity[ci] < f.threshold - 2 * f.working_noise;
      deepest = std::min(deepest, d.min_intensity[ci]);
    }
    ASSERT_GT(deep, 50);
    EXPECT_GE(f.shadows.value, 0.75 * deep) << full.cameras[ci].id << " in view " << in_view;
    EXPECT_LE(f.shadows.value, static_cast<double>(in_view)) << full.cameras[ci].id;
    EXPECT_NEAR(f.min_intensity.value, deepest, 0.1);
    EXPECT_EQ(f.shadow_coverage.flag, Flag::green);
    EXPECT_NEAR(f.shadows_per_mpx, 1e6 * f.shadows.value / (2560.0 * 2160.0), 1e-9) << "per frame Mpx";
  }
}

TEST(ShadowLook, AutomaticBinningKeepsTheWorkingImageNearTheReducedSize) {
  const ShadowLookOptions o;
  EXPECT_EQ(o.binning_for(640, 540), 1);
  EXPECT_EQ(o.binning_for(1280, 1080), 2);
  EXPECT_EQ(o.binning_for(2048, 2048), 4);
  EXPECT_EQ(o.binning_for(2560, 2160), 4);
  ShadowLookOptions fixed;
  fixed.binning = 2;
  EXPECT_EQ(fixed.binning_for(2560, 2160), 2);
}

// Every figure is judged against its target, so a rig's targets change the flags and only them.
TEST(ShadowLook, TargetsDecideTheFlags) {
  const sim::SprayCase c = reduced_case(1.0, 5);
  const sim::SpraySet s = sim::render_spray_set(c, 1);
  const Image& frame = s.frames.cameras[0].a.image;
  ShadowFrame plain;
  ShadowLook(ShadowLookOptions{}).analyse(frame, plain);
  EXPECT_EQ(plain.overall(), Flag::green);
  EXPECT_EQ(plain.shadows.flag, Flag::green) << "no count target: not judged";
  EXPECT_EQ(plain.min_intensity.flag, Flag::green);
  const double count = plain.shadows.value;

  ShadowLookOptions strict;
  strict.targets.shadow_count = Target{2 * count, 4 * count, ShadowTargets::shadow_count_amber};
  strict.targets.min_intensity = Target{0.0, 0.5 * plain.min_intensity.value, ShadowTargets::min_intensity_amber};
  strict.targets.bright_fraction = Target{0.2, 0.9, 0.1};
  strict.targets.shadow_coverage = Target{0.0, 0.25 * plain.shadow_coverage.value, 1.0};
  strict.targets.uniformity = Target{std::min(1.0, plain.uniformity.value * 1.5), 1.0, 0.1};
  ShadowFrame judged;
  ShadowLook(strict).analyse(frame, judged);
  EXPECT_EQ(judged.shadows.value, count) << "targets change flags, not figures";
  EXPECT_EQ(judged.shadows.flag, Flag::red);
  EXPECT_EQ(judged.min_intensity.flag, Flag::red);
  EXPECT_EQ(judged.bright_fraction.flag, Flag::red) << judged.bright_fraction.value;
  EXPECT_EQ(judged.shadow_coverage.flag, Flag::red);
  EXPECT_EQ(judged.uniformity.flag, Flag::red);
  const nlohmann::json j = judged;
  EXPECT_EQ(j.at("shadows").at("count_flag"), "red");
  EXPECT_EQ(j.at("shadows").at("min_intensity_flag"), "red");
  EXPECT_EQ(j.at("bright_field").at("fraction_flag"), "red");
  EXPECT_EQ(j.at("flag"), "red");

  // A count target the frame meets is green.
  ShadowLookOptions met;
  met.targets.shadow_count = Target{0.5 * count, 2 * count, ShadowTargets::shadow_count_amber};
  ShadowFrame ok;
  ShadowLook(met).analyse(frame, ok);
  EXPECT_EQ(ok.shadows.flag, Flag::green);
}

TEST(ShadowLook, BadFramesAndOptionsAreNamed) {
  ShadowLook look;
  ShadowFrame f;
  EXPECT_THROW(look.analyse(Image(), f), Error);
  const Image small = Image::allocate(8, 8, SampleType::u16);
  try {
    look.analyse(small, f);
    FAIL() << "an 8 x 8 frame was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("too small"), std::string::npos) << e.what();
  }
  EXPECT_THROW(look.analyse(Image::allocate(32, 32, SampleType::f32), f), Error);
  ShadowLookOptions o;
  o.shadow_sigmas = 0.5;
  try {
    ShadowLook bad(o);
    FAIL() << "shadow_sigmas 0.5 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shadow_sigmas"), std::string::npos) << e.what();
  }
  ShadowLookOptions wide;
  wide.binning = 9;
  try {
    ShadowLook bad(wide);
    FAIL() << "binning 9 was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("binning = 9"), std::string::npos) << e.what();
  }
  ShadowLookOptions count;
  count.targets.shadow_count = Target{500, 100, 0.25};
  try {
    ShadowLook bad(count);
    FAIL() << "a reversed count range was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shadow_count"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tomorig::quicklook
