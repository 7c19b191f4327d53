// Quick-look statistics: saturation, energy balance, focus, local background, flags, bad input
// and the no-allocation-per-frame promise, each against what the simulator rendered.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "particle_field.h"
#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/statistics.h"

// Counts heap allocations while `counting` is set: this test binary is linked with
// -Wl,--wrap=malloc (tests/processing/CMakeLists.txt), so every malloc of the program's own
// code, the global operator new included, passes through here.
namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
}  // namespace

extern "C" void* __real_malloc(std::size_t size);
extern "C" void* __wrap_malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
  return __real_malloc(size);
}

namespace tomorig::quicklook {
namespace {

using testing::FieldSpec;
using testing::make_field;

// The signal of `spec`'s particles with x < split rendered at sigma_left, the rest at
// sigma_right: a frame whose right part is out of focus.
Image half_blurred(const FieldSpec& spec, double split, double sigma_left, double sigma_right) {
  const auto particles = testing::random_particles(spec);
  std::vector<sim::ParticleImage> left, right;
  for (const auto& p : particles) (p.centre.x < split ? left : right).push_back(p);
  FieldSpec l = spec, r = spec;
  l.sigma_px = sigma_left;
  r.sigma_px = sigma_right;
  Image signal = testing::render(left, l);
  const Image blurred = testing::render(right, r);
  for (int y = 0; y < signal.height(); ++y)
    for (int x = 0; x < signal.width(); ++x) signal.at<float>(x, y) += blurred.at<float>(x, y);
  return testing::digitise(signal, spec, 99);
}

TEST(QuickLook, SaturationFractionAndMapMatchTheRenderedSignal) {
  FieldSpec spec;
  spec.bit_depth = 12;  // Mono12 in 16-bit samples: saturates at 4095
  spec.peak_counts = 6000;
  spec.noise = false;
  spec.ppp = 0.02;
  const auto field = make_field(spec);
  // Truth from the noise-free signal: a pixel saturates where signal + black level rounds to
  // full scale or beyond.
  double saturated = 0;
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) saturated += field.signal.at<float>(x, y) + spec.offset_counts >= 4094.5 ? 1 : 0;
  const double truth = saturated / (spec.width * spec.height);
  ASSERT_GT(truth, 0.001);

  QuickLookOptions options;
  options.bit_depth = 12;
  QuickLook ql(options);
  FrameStatistics s;
  ql.analyse(field.image, s);
  EXPECT_EQ(s.full_scale, 4095);
  EXPECT_DOUBLE_EQ(s.saturated_fraction.value, truth);
  EXPECT_EQ(s.saturated_fraction.flag, truth > 0.01 ? Flag::red : Flag::amber);
  // The map adds up to the same count.
  double from_map = 0;
  for (int j = 0; j < s.saturation_map.tiles_y; ++j)
    for (int i = 0; i < s.saturation_map.tiles_x; ++i) from_map += s.saturation_map.at(i, j) * 64 * 64;
  EXPECT_NEAR(from_map, saturated, 1e-3 * saturated);
  // The last display bin holds the saturated pixels.
  EXPECT_GE(s.histogram.back(), static_cast<std::uint32_t>(saturated));

  // The same frame read as 16-bit data is not saturated.
  QuickLook sixteen;
  sixteen.analyse(field.image, s);
  EXPECT_EQ(s.saturated_fraction.value, 0.0);
  EXPECT_EQ(s.saturated_fraction.flag, Flag::green);
}

TEST(QuickLook, EnergyBalanceIsTheRatioOfTheLightOfBToA) {
  QuickLook ql;
  CameraQuickLook s;
  for (const double ratio : {1.0, 0.8, 0.5}) {
    FieldSpec a, b;
    a.seed = 3;
    b.seed = 4;
    b.peak_counts = a.peak_counts * ratio;
    ql.analyse(make_field(a).image, make_field(b).image, s);
    EXPECT_NEAR(s.energy_balance.value, ratio, 0.03 * ratio) << ratio;
    EXPECT_EQ(s.energy_balance.flag, ratio == 1.0 ? Flag::green : ratio == 0.8 ? Flag::amber : Flag::red) << ratio;
  }
}

TEST(QuickLook, BlurredHalfOfTheFrameShowsInTheFocusMap) {
  FieldSpec spec;
  spec.ppp = 0.03;
  QuickLook ql;
  FrameStatistics sharp, blurred;
  ql.analyse(half_blurred(spec, 1e9, 0.75, 0.75), sharp);
  EXPECT_LT(sharp.soft_tile_fraction.value, 0.05);
  EXPECT_EQ(sharp.soft_tile_fraction.flag, Flag::green);
  const auto [lowest, highest] = std::minmax_element(sharp.focus_map.values.begin(), sharp.focus_map.values.end());
  EXPECT_LT(*highest, 1.3 * *lowest);  // one focus everywhere: a flat map

  // Right of x = 256 (tile columns 4..7) the particle images are 8 px instead of 3 px wide.
  ql.analyse(half_blurred(spec, 256, 0.75, 2.0), blurred);
  const TileMap& map = blurred.focus_map;
  for (int j = 0; j < map.tiles_y; ++j)
    for (int i = 0; i < 4; ++i) EXPECT_GT(map.at(i, j), 2 * map.at(i + 4, j)) << "tile " << i << ", " << j;
  EXPECT_NEAR(blurred.soft_tile_fraction.value, 0.5, 0.07);
  EXPECT_EQ(blurred.soft_tile_fraction.flag, Flag::red);
}

// A frame with more tiles than detail_tiles: d_tau, the autocovariance ppp and focus come from
// one tile in every block of tiles, and the focus map has one value per block. Here 16 sample
// tiles of the 64 of a 512 px frame (blocks of 2 x 2 tiles).
TEST(QuickLook, SampleTilesKeepTheFiguresAndMapTheFocusPerBlock) {
  FieldSpec spec;
  spec.ppp = 0.03;
  QuickLookOptions options;
  options.detail_tiles = 16;
  QuickLook ql(options);
  FrameStatistics s;
  const Image image = half_blurred(spec, 256, 0.75, 2.0);
  ql.analyse(image, s);
  ASSERT_EQ(s.focus_map.tiles_x, 4);
  ASSERT_EQ(s.focus_map.tiles_y, 4);
  EXPECT_EQ(s.focus_map.tile_px, 128);
  EXPECT_EQ(s.background_map.tiles_x, 8);  // the other maps keep every tile
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 2; ++i) EXPECT_GT(s.focus_map.at(i, j), 2 * s.focus_map.at(i + 2, j)) << i << ", " << j;
  EXPECT_NEAR(s.soft_tile_fraction.value, 0.5, 0.07);

  // Sharp everywhere: d_tau and ppp from the sample as from every tile, both against truth.
  const auto field = make_field(spec);
  ql.analyse(field.image, s);
  EXPECT_NEAR(s.diameter_px.value, 3.0, 0.3);
  EXPECT_NEAR(s.ppp.value, field.true_ppp(), 0.10 * field.true_ppp());
}

// A frame whose sides are no multiple of the tile (partial last tiles and a sample lattice
// whose last block is partial): every figure still agrees with the truth, with every tile
// sampled and with a few.
TEST(QuickLook, OddFrameSizesAreMeasuredToTheEdges) {
  FieldSpec spec;
  spec.width = 1030;  // 16 tiles of 64 px and one of 6
  spec.height = 771;  // 12 tiles and one of 3
  const auto field = make_field(spec);
  for (const int detail_tiles : {256, 16}) {
    QuickLookOptions options;
    options.detail_tiles = detail_tiles;
    QuickLook ql(options);
    FrameStatistics s;
    ql.analyse(field.image, s);
    EXPECT_EQ(s.background_map.tiles_x, 17);
    EXPECT_EQ(s.background_map.tiles_y, 13);
    EXPECT_LE(s.focus_map.tiles_x * s.focus_map.tiles_y, detail_tiles);
    EXPECT_NEAR(s.ppp.value, field.true_ppp(), 0.10 * field.true_ppp()) << detail_tiles;
    EXPECT_NEAR(s.diameter_px.value, 3.0, 0.3) << detail_tiles;
    EXPECT_NEAR(s.background, spec.offset_counts, 2.0) << detail_tiles;
    EXPECT_NEAR(s.noise, spec.read_noise_e, 0.75) << detail_tiles;
    std::size_t focus = 0;
    for (const float f : s.focus_map.values) focus += std::isfinite(f) ? 1 : 0;
    EXPECT_GT(focus, s.focus_map.values.size() * 3 / 4) << detail_tiles;
  }
}

TEST(QuickLook, LocalBackgroundFollowsAGradient) {
  FieldSpec spec;
  spec.ppp = 0.02;  // sparse: the particles' own lift of the background stays small (accuracy test)
  const auto field = make_field(spec);
  // Add a ramp of 0 .. 30 counts (6 noise sigma) across the frame to the signal, as stray light.
  // Each tile's level within 1.5 sigma (7.5 counts) of the ramp at its centre, and no bias.
  Image signal = field.signal.clone();
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x) signal.at<float>(x, y) += 30.0f * static_cast<float>(x) / spec.width;
  const Image image = testing::digitise(signal, spec, 5);
  QuickLook ql;
  FrameStatistics s;
  ql.analyse(image, s);
  double error_sum = 0;
  for (int i = 0; i < s.background_map.tiles_x; ++i) {
    const double truth = spec.offset_counts + 30.0 * (i * 64 + 32) / spec.width;
    for (int j = 0; j < s.background_map.tiles_y; ++j) {
      EXPECT_NEAR(s.background_map.at(i, j), truth, 7.5) << i << "," << j;
      error_sum += s.background_map.at(i, j) - truth;
    }
  }
  EXPECT_NEAR(error_sum / 64, 0.0, 1.0);  // no bias across the ramp
  EXPECT_NEAR(s.ppp.value, field.true_ppp(), 0.10 * field.true_ppp());
  EXPECT_NEAR(s.diameter_px.value, 3.0, 0.3);
}

TEST(QuickLook, FlagsFollowTheTargets) {
  QuickLook ql;
  FrameStatistics s;
  FieldSpec good;  // 0.04 ppp, d_tau 2.5 px, Ns 0.2: all inside the targets
  good.ppp = 0.04;
  good.sigma_px = 0.625;
  ql.analyse(make_field(good).image, s);
  EXPECT_EQ(s.ppp.flag, Flag::green);
  EXPECT_EQ(s.diameter_px.flag, Flag::green);
  EXPECT_EQ(s.source_density.flag, Flag::green);
  EXPECT_EQ(s.saturated_fraction.flag, Flag::green);
  EXPECT_EQ(s.overall(), Flag::green);

  FieldSpec sparse = good;
  sparse.ppp = 0.005;
  ql.analyse(make_field(sparse).image, s);
  EXPECT_EQ(s.ppp.flag, Flag::red);
  EXPECT_EQ(s.overall(), Flag::red);

  FieldSpec big = good;
  big.sigma_px = 1.0;  // d_tau 4 px: above 3 * 1.25
  ql.analyse(make_field(big).image, s);
  EXPECT_EQ(s.diameter_px.flag, Flag::red);
  EXPECT_EQ(s.source_density.flag, Flag::red);  // 0.04 * pi / 4 * 16 = 0.5

  // A frame without particles: nothing to measure is red, not a number.
  FieldSpec empty = good;
  empty.ppp = 1e-9;
  ql.analyse(make_field(empty).image, s);
  EXPECT_LT(s.ppp.value, 1e-4);
  EXPECT_EQ(s.ppp.flag, Flag::red);
  EXPECT_FALSE(s.diameter_px.measured());
  EXPECT_EQ(s.diameter_px.flag, Flag::red);
  EXPECT_NEAR(s.background, good.offset_counts, 1.0);
  EXPECT_NEAR(s.noise, good.read_noise_e, 0.5);
}

TEST(QuickLook, TargetsAndJudgement) {
  const Target t{2.0, 3.0, 0.25};
  EXPECT_EQ(judge(2.5, t), Flag::green);
  EXPECT_EQ(judge(2.0, t), Flag::green);
  EXPECT_EQ(judge(3.7, t), Flag::amber);
  EXPECT_EQ(judge(1.7, t), Flag::amber);
  EXPECT_EQ(judge(3.8, t), Flag::red);
  EXPECT_EQ(judge(1.5, t), Flag::red);
  EXPECT_EQ(judge(std::nan(""), t), Flag::red);
  EXPECT_EQ(worst(Flag::amber, Flag::green), Flag::amber);
  EXPECT_FALSE(Target({3.0, 2.0, 0.25}).validate("x").empty());
  EXPECT_FALSE(Target({0.0, 0.0, 0.25}).validate("x").empty());
  EXPECT_FALSE(Target({1.0, 2.0, -1.0}).validate("x").empty());
  EXPECT_TRUE(t.validate("x").empty());
}

TEST(QuickLook, Mono8FramesWork) {
  FieldSpec spec;
  spec.peak_counts = 200;
  spec.offset_counts = 10;
  spec.read_noise_e = 2;
  const auto field = make_field(spec);
  Image mono8 = Image::allocate(spec.width, spec.height, SampleType::u8);
  for (int y = 0; y < spec.height; ++y)
    for (int x = 0; x < spec.width; ++x)
      mono8.at<std::uint8_t>(x, y) = static_cast<std::uint8_t>(std::min<int>(255, field.image.at<std::uint16_t>(x, y)));
  QuickLook ql;
  FrameStatistics s;
  ql.analyse(mono8, s);
  EXPECT_EQ(s.full_scale, 255);
  EXPECT_NEAR(s.ppp.value, field.true_ppp(), 0.10 * field.true_ppp());
  EXPECT_NEAR(s.diameter_px.value, 3.0, 0.3);
  EXPECT_NEAR(s.background, 10.0, 1.0);
}

TEST(QuickLook, BadInputIsRefusedWithAClearMessage) {
  QuickLook ql;
  FrameStatistics s;
  CameraQuickLook c;
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { ql.analyse(Image(), s); }).find("missing"), std::string::npos);
  EXPECT_NE(message([&] { ql.analyse(Image::allocate(64, 64, SampleType::f32), s); }).find("float"), std::string::npos);
  EXPECT_NE(message([&] { ql.analyse(Image::allocate(4, 64, SampleType::u16), s); }).find("at least"),
            std::string::npos);
  EXPECT_NE(message([&] {
              ql.analyse(Image::allocate(64, 64, SampleType::u16), Image::allocate(64, 32, SampleType::u16), c);
            }).find("differ"),
            std::string::npos);
  EXPECT_NE(message([&] { ql.analyse(Image::allocate(64, 64, SampleType::u16), Image(), c); }).find("frame B"),
            std::string::npos);
  QuickLookOptions bad;
  bad.tile_px = 8;
  EXPECT_NE(message([&] { QuickLook q(bad); }).find("tile_px"), std::string::npos);
  bad = {};
  bad.detail_tiles = 0;
  EXPECT_NE(message([&] { QuickLook q(bad); }).find("detail_tiles"), std::string::npos);
  bad = {};
  bad.targets.ppp = {0.08, 0.02, 0.25};
  EXPECT_NE(message([&] { QuickLook q(bad); }).find("quicklook.ppp"), std::string::npos);
  bad = {};
  bad.bit_depth = 12;
  QuickLook twelve(bad);
  EXPECT_NE(message([&] { twelve.analyse(Image::allocate(64, 64, SampleType::u8), s); }).find("Mono8"),
            std::string::npos);
}

TEST(QuickLook, FramesOfAnUnchangedSizeAllocateNothing) {
  FieldSpec spec;
  const Image a = make_field(spec).image;
  spec.seed = 2;
  const Image b = make_field(spec).image;
  QuickLook ql;
  CameraQuickLook s;
  ql.analyse(a, b, s);  // the first frame sizes the buffers
  allocations = 0;
  counting = true;
  for (int n = 0; n < 3; ++n) ql.analyse(b, a, s);
  counting = false;
  EXPECT_EQ(allocations.load(), 0);
}

}  // namespace
}  // namespace tomorig::quicklook
