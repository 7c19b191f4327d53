// The Δt check against simulator truth: a known uniform shift, and the tpiv-thesis cameras
// rendered at a rig's pulse separation and at 3x it (issue 16: the check must flag the latter).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "particle_field.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/dt_check.h"
#include "tomorig/processing/calibration/pinhole_camera.h"
#include "tomorig/simulators/cases.h"
#include "tomorig/simulators/flow.h"
#include "tomorig/simulators/light_sheet.h"
#include "tomorig/simulators/scene.h"

namespace tomorig::quicklook {
namespace {

using testing::FieldSpec;

// Frames A and B of one particle field, B shifted by (dx, dy) px.
std::pair<Image, Image> shifted_pair(double dx, double dy, std::uint64_t seed = 1) {
  FieldSpec spec;
  spec.seed = seed;
  auto particles = testing::random_particles(spec);
  const Image a = testing::digitise(testing::render(particles, spec), spec, 11);
  for (auto& p : particles) p.centre = {p.centre.x + dx, p.centre.y + dy};
  const Image b = testing::digitise(testing::render(particles, spec), spec, 12);
  return {a, b};
}

TEST(DtCheck, UniformShiftIsMeasuredAndJudged) {
  DtCheck check;
  DtCheckResult r;
  struct Case {
    double dx, dy;
    Flag flag;
  };
  for (const Case k : {Case{4.3, -2.6, Flag::green}, Case{0.4, 0.2, Flag::red}, Case{17.0, 6.5, Flag::red},
                       Case{2.5, 0.0, Flag::amber}}) {
    const auto [a, b] = shifted_pair(k.dx, k.dy);
    check.check(a, b, r);
    EXPECT_EQ(r.valid_fraction.value, 1.0) << k.dx;
    EXPECT_NEAR(r.median_dx, k.dx, 0.1) << k.dx;
    EXPECT_NEAR(r.median_dy, k.dy, 0.1) << k.dx;
    EXPECT_NEAR(r.displacement_px.value, std::hypot(k.dx, k.dy), 0.1) << k.dx;
    EXPECT_GT(r.median_peak_ratio, 3.0) << k.dx;
    EXPECT_EQ(r.overall(), k.flag) << k.dx;
    // Every window lands in the histogram bins within 0.2 px of the shift.
    const double m = std::hypot(k.dx, k.dy);
    std::uint32_t near = 0;
    for (auto bin = static_cast<std::size_t>(m - 0.2); bin <= static_cast<std::size_t>(m + 0.2); ++bin)
      near += r.displacement_histogram[bin];
    EXPECT_EQ(near, 16u) << k.dx;
  }
}

TEST(DtCheck, UncorrelatedFramesAreInvalid) {
  const auto [a, unused] = shifted_pair(0, 0, 1);
  const auto [other, unused2] = shifted_pair(0, 0, 2);  // a different particle field
  DtCheck check;
  DtCheckResult r;
  check.check(a, other, r);
  EXPECT_LT(r.valid_fraction.value, 0.2);
  EXPECT_EQ(r.valid_fraction.flag, Flag::red);
  EXPECT_EQ(r.overall(), Flag::red);
}

// A tunnel-like flow: uniform convection along x with a 20 % shear across y and a small
// z component, coherent through the depth of the light sheet (unlike tpiv-thesis' Taylor-Green
// vortices, whose displacement reverses through the depth: docs/accuracy.md).
class ConvectionFlow final : public sim::Flow {
 public:
  explicit ConvectionFlow(double u_mm) : u_(u_mm) {}
  std::string name() const override { return "convection"; }
  std::string parameters_json() const override { return "{}"; }
  Vec3d displacement(const Vec3d& p) const override {
    return {u_ * (1.0 + 0.2 * std::sin(2 * M_PI * p.y / 10.0)), 0.0, 0.1 * u_};
  }

 private:
  double u_;
};

// The tpiv-thesis cameras and slab with the flow above, rendered through the simulator library
// (particles, straddling, camera projection, sensor) at a pulse separation `dt_factor` times
// the rig's: 6 px of convection at dt_factor 1 (1 px = 0.0195 mm at the volume centre).
std::vector<std::pair<Image, Image>> render_convection(double dt_factor) {
  const sim::CaseDefinition& thesis = sim::find_case("tpiv-thesis");
  const ConvectionFlow flow(dt_factor * 6.0 * 0.0195);
  const auto particles = sim::uniform_particles(thesis.slab, 13107, 21);  // 0.05 ppp
  const sim::ParticlePair pair = sim::straddle(particles, flow);
  const sim::LightSheet sheet = sim::LightSheet::for_slab(sim::LightSheetProfile::uniform, thesis.slab);
  sim::ParticleImageOptions image_options;
  image_options.sigma_px = thesis.sigma_px;
  sim::SensorOptions sensor;
  sensor.noise = true;
  std::vector<std::pair<Image, Image>> out;
  std::uint64_t seed = 0;
  for (const sim::SimulatedCameraSpec& c : thesis.cameras) {
    const auto model = calibration::PinholeCamera::yawed(c.yaw_deg, c.focal_length_mm, c.pixel_pitch_um,
                                                         c.distance_mm, c.width, c.height);
    std::pair<Image, Image> frames;
    for (const auto* positions : {&pair.a, &pair.b}) {
      Image signal = Image::allocate(c.width, c.height, SampleType::f32);
      sim::render_particles(model, *positions, sheet, image_options, signal);
      (positions == &pair.a ? frames.first : frames.second) = sim::digitise(signal, sensor, ++seed);
    }
    out.push_back(std::move(frames));
  }
  return out;
}

TEST(DtCheck, ThreeTimesTooLongIsFlagged) {
  DtCheck check;
  DtCheckResult r;
  for (const double factor : {1.0, 3.0}) {
    const auto cameras = render_convection(factor);
    for (std::size_t c = 0; c < cameras.size(); ++c) {
      check.check(cameras[c].first, cameras[c].second, r);
      std::printf("| %.0fx | cam%zu | %.2f | %.1f | %.2f | %s |\n", factor, c, r.valid_fraction.value,
                  r.median_peak_ratio, r.displacement_px.value, std::string(to_string(r.overall())).c_str());
      if (factor == 1.0) {
        EXPECT_EQ(r.overall(), Flag::green) << "camera " << c;
      } else {
        EXPECT_NE(r.overall(), Flag::green) << "camera " << c;
        EXPECT_GT(r.displacement_px.value, 12.0) << "camera " << c;
      }
    }
  }
}

TEST(DtCheck, BadInputIsRefused) {
  DtCheck check;
  DtCheckResult r;
  const Image small = Image::allocate(32, 32, SampleType::u16);
  EXPECT_THROW(check.check(small, small, r), Error);
  const Image a = Image::allocate(128, 128, SampleType::u16), b = Image::allocate(128, 96, SampleType::u16);
  EXPECT_THROW(check.check(a, b, r), Error);
  EXPECT_THROW(check.check(a, Image(), r), Error);
  DtCheckOptions bad;
  bad.window_px = 4;
  EXPECT_THROW(DtCheck{bad}, Error);
  bad = {};
  bad.displacement_px = {12, 3, 0.25};
  EXPECT_THROW(DtCheck{bad}, Error);
  // Flat frames: no window has anything to correlate.
  check.check(a, a, r);
  EXPECT_EQ(r.valid_fraction.value, 0.0);
  EXPECT_FALSE(r.displacement_px.measured());
}

}  // namespace
}  // namespace tomorig::quicklook
