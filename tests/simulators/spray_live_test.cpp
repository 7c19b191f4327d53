// spray-thesis as a live rig renders it (issue 20): an event's actual pulse separation scales
// the droplets' displacement around unchanged mid-time positions, the case's own separation
// gives the whole-session images bit for bit, and pulse_b_energy sets pulse B's LED energy.
#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/simulators/spray.h"

namespace tomorig::sim {
namespace {

SprayCase small_case(double pulse_b_energy = 1.0) {
  SprayOptions o;
  o.reduced = true;
  o.seed = 4;
  o.droplets = 60;
  o.noise = false;
  o.pulse_jitter = 0.0;
  o.pulse_b_energy = pulse_b_energy;
  return make_spray_thesis_case(o);
}

TEST(SprayLive, TheCasesOwnSeparationGivesTheSessionImagesBitForBit) {
  const SprayCase c = small_case();
  const SpraySet session = render_spray_set(c, 2), live = render_spray_set(c, 2, 1700);
  ASSERT_EQ(live.frames.dt_ns, 1700);
  for (std::size_t ci = 0; ci < c.cameras.size(); ++ci) {
    EXPECT_TRUE(live.frames.cameras[ci].a.image.same_pixels(session.frames.cameras[ci].a.image));
    EXPECT_TRUE(live.frames.cameras[ci].b.image.same_pixels(session.frames.cameras[ci].b.image));
  }
}

TEST(SprayLive, AnEventsSeparationScalesTheDisplacementAroundTheSameMidpoints) {
  const SprayCase c = small_case();
  const SpraySet nominal = render_spray_set(c, 1, 1700), doubled = render_spray_set(c, 1, 3400);
  EXPECT_EQ(doubled.frames.dt_ns, 3400);
  EXPECT_EQ(doubled.frames.cameras[0].b.timestamp_ns - doubled.frames.cameras[0].a.timestamp_ns, 3400);
  ASSERT_EQ(nominal.droplets.size(), doubled.droplets.size());
  for (std::size_t i = 0; i < nominal.droplets.size(); ++i) {
    const Droplet &n = nominal.droplets[i], &d = doubled.droplets[i];
    EXPECT_EQ(n.d_um, d.d_um);
    const Vec3d mid_n = (n.a + n.b) * 0.5, mid_d = (d.a + d.b) * 0.5, step_n = n.b - n.a, step_d = d.b - d.a;
    EXPECT_NEAR(mid_d.x, mid_n.x, 1e-12);
    EXPECT_NEAR(mid_d.y, mid_n.y, 1e-12);
    EXPECT_NEAR(step_d.x, 2 * step_n.x, 1e-12);
    EXPECT_NEAR(step_d.y, 2 * step_n.y, 1e-12);
    EXPECT_NEAR(step_d.z, 2 * step_n.z, 1e-12);
  }
  EXPECT_THROW(render_spray_set(c, 1, -5), Error);
}

TEST(SprayLive, PulseBEnergySetsTheSecondPulse) {
  const SprayCase c = small_case(0.8);
  const SpraySet s = render_spray_set(c, 0);
  for (std::size_t ci = 0; ci < c.cameras.size(); ++ci) {
    EXPECT_DOUBLE_EQ(s.pulse_energy_a[ci], 1.0);
    EXPECT_DOUBLE_EQ(s.pulse_energy_b[ci], 0.8);
  }
  SprayOptions bad;
  bad.pulse_b_energy = 0.0;
  EXPECT_THROW(make_spray_thesis_case(bad), Error);
}

}  // namespace
}  // namespace tomorig::sim
