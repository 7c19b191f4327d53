// Particle images: flux, centroid and determinism, checked against closed forms.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/particle_renderer.h"

namespace {

using tomorig::Image;
using tomorig::SampleType;
using tomorig::Vec2d;
using tomorig::sim::ParticleImage;
using tomorig::sim::ParticleImageOptions;

constexpr double kPi = 3.14159265358979323846;

struct Moments {
  double sum = 0, cx = 0, cy = 0, peak = 0;
};

Moments moments(const Image& img) {
  Moments m;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const double v = img.value(x, y);
      m.sum += v;
      m.cx += v * x;
      m.cy += v * y;
      m.peak = std::max(m.peak, v);
    }
  m.cx /= m.sum;
  m.cy /= m.sum;
  return m;
}

Image render_one(const Vec2d& centre, const ParticleImageOptions& opt, int size = 64) {
  Image img = Image::allocate(size, size, SampleType::f32);
  const ParticleImage p{centre, opt.peak_counts};
  tomorig::sim::render_particle_images({&p, 1}, opt, img);
  return img;
}

TEST(ParticleRenderer, SingleParticleIntegratesToPeakTimesTwoPiSigmaSquaredAtItsCentre) {
  ParticleImageOptions opt;  // sigma 0.75 px (4 sigma = 3 px), peak 1000
  const double expected_flux = opt.peak_counts * 2 * kPi * 0.75 * 0.75;
  const Vec2d centres[] = {{30, 30}, {30.5, 30.5}, {30.25, 31.75}, {29.01, 30.99}, {31.37, 30.62}, {30.49, 29.13}};
  for (const Vec2d& c : centres) {
    const Moments m = moments(render_one(c, opt));
    EXPECT_NEAR(m.sum / expected_flux, 1.0, 1e-4) << c.x << ", " << c.y;
    EXPECT_NEAR(m.cx, c.x, 0.01) << c.x << ", " << c.y;
    EXPECT_NEAR(m.cy, c.y, 0.01) << c.x << ", " << c.y;
    EXPECT_LE(m.peak, opt.peak_counts);  // pixel-integrated: never above the continuous peak
  }
}

TEST(ParticleRenderer, PixelValueIsTheIntegralOverThePixel) {
  // Centre pixel of a particle at a pixel centre: peak * 2 pi s^2 * (erf(0.5/(sqrt2 s)))^2.
  ParticleImageOptions opt;
  const Image img = render_one({20, 20}, opt);
  const double g = std::erf(0.5 / (std::sqrt(2.0) * 0.75));
  EXPECT_NEAR(img.value(20, 20), 1000.0 * 2 * kPi * 0.75 * 0.75 * g * g, 1e-3);
  EXPECT_DOUBLE_EQ(img.value(19, 20), img.value(21, 20));  // symmetric
}

TEST(ParticleRenderer, ParticlesAddAndEdgesClip) {
  ParticleImageOptions opt;
  const double flux = opt.peak_counts * 2 * kPi * 0.75 * 0.75;
  Image img = Image::allocate(32, 32, SampleType::f32);
  const std::vector<ParticleImage> ps{{{10, 10}, 1000}, {{10.3, 10.2}, 500}, {{-0.0, 16}, 1000},
                                      {{500, 500}, 1000}, {{NAN, 3}, 1000}};
  tomorig::sim::render_particle_images(ps, opt, img);
  // Two whole particles plus half of the one centred on the left edge pixel column's centre
  // (x = 0: the image starts at -0.5, so slightly more than half is inside).
  const double left_fraction = 0.5 * (1 + std::erf(0.5 / (std::sqrt(2.0) * 0.75)));
  EXPECT_NEAR(moments(img).sum / (flux * (1.5 + left_fraction)), 1.0, 1e-4);
}

TEST(ParticleRenderer, ThreadCountDoesNotChangeTheImage) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> pos(-3, 259);
  std::vector<ParticleImage> ps(20000);
  for (auto& p : ps) p = {{pos(rng), pos(rng)}, 1000};
  ParticleImageOptions opt;
  opt.threads = 1;
  Image one = Image::allocate(256, 256, SampleType::f32);
  tomorig::sim::render_particle_images(ps, opt, one);
  for (int threads : {2, 3, 8}) {
    opt.threads = threads;
    Image many = Image::allocate(256, 256, SampleType::f32);
    tomorig::sim::render_particle_images(ps, opt, many);
    EXPECT_TRUE(one.same_pixels(many)) << threads << " threads";
  }
}

TEST(ParticleRenderer, RejectsBadOptionsAndImages) {
  ParticleImageOptions opt;
  opt.sigma_px = 0;
  Image img = Image::allocate(8, 8, SampleType::f32);
  EXPECT_THROW(tomorig::sim::render_particle_images({}, opt, img), tomorig::Error);
  Image u16 = Image::allocate(8, 8, SampleType::u16);
  EXPECT_THROW(tomorig::sim::render_particle_images({}, ParticleImageOptions{}, u16), tomorig::Error);
}

}  // namespace
