// The shadow preprocessing presets A and B (thesis Sect. 7.4) and the local flat-field they use,
// on shadow images whose right output is known by construction.
#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/chain_spec.h"
#include "tomorig/processing/preprocess/image_chain.h"

namespace tomorig::preprocess {
namespace {

constexpr int kW = 256, kH = 192;

// A bright field falling off by 20 % towards the right edge, with noise of relative sigma
// `noise`, and dark round shadows (depth `depth`, radius 2 px) at the given centres.
Image shadow_image(double noise, double depth, const std::vector<std::pair<int, int>>& shadows, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  Image image = Image::allocate(kW, kH, SampleType::u16);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double bright = 3000.0 * (1.0 - 0.2 * x / (kW - 1.0));
      double v = bright * (1.0 + noise * gauss(rng));
      for (const auto& [sx, sy] : shadows)
        if ((x - sx) * (x - sx) + (y - sy) * (y - sy) <= 4) v *= 1.0 - depth;
      image.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(std::lround(v));
    }
  return image;
}

TEST(ShadowPresets, NamesParseAsChainsAndFollowTheThesisOrder) {
  const ChainSpec a = read_chain("shadow-a");
  ASSERT_EQ(a.steps.size(), 3u);
  EXPECT_EQ(a.steps[0].kind, StepKind::normalize);
  EXPECT_EQ(a.steps[0].by, NormalizeBy::local);
  EXPECT_EQ(a.steps[1].kind, StepKind::invert);
  EXPECT_EQ(a.steps[2].kind, StepKind::clip);
  EXPECT_TRUE(a.steps[2].use_sigmas);
  EXPECT_DOUBLE_EQ(a.steps[2].sigmas, 2.0);
  EXPECT_TRUE(a.steps[2].subtract);
  const ChainSpec b = read_chain("shadow-b");
  ASSERT_EQ(b.steps.size(), 5u);  // A, then the 20 x 20 local minimum and a constant threshold
  EXPECT_EQ(b.steps[3].kind, StepKind::subtract_local_minimum);
  EXPECT_EQ(b.steps[3].size, 20);
  EXPECT_EQ(b.steps[4].kind, StepKind::clip);
  EXPECT_FALSE(b.steps[4].use_sigmas);
  // The text a results file records is the preset's; a file name is still read as a file.
  EXPECT_NE(chain_text("shadow-b").find("subtract_local_minimum"), std::string::npos);
  const ChainSpec d = read_chain("shadow-detect");  // A with the offset at 0 sigma
  ASSERT_EQ(d.steps.size(), 3u);
  EXPECT_DOUBLE_EQ(d.steps[2].sigmas, 0.0);
  EXPECT_THROW(read_chain("shadow-c"), Error);
  try {
    chain_text("no-such-chain.toml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shadow-a"), std::string::npos) << e.what();
  }
}

TEST(ShadowPresets, LocalNormalizeFlattensAVignettedBrightField) {
  Step s;
  s.kind = StepKind::normalize;
  s.by = NormalizeBy::local;
  s.size = 32;
  s.target = 1000;
  ImageChain chain(ChainSpec{{s}});
  const Image& out = chain.run(shadow_image(0.0, 0.0, {}, 1), Exposure::A);
  // The fall-off is linear, so tile medians interpolated linearly reproduce it (within the
  // rounding to counts) except in the outer half-tiles, where the level is held.
  for (int y = 16; y < kH - 16; y += 7)
    for (int x = 16; x < kW - 16; x += 5) EXPECT_NEAR(out.at<float>(x, y), 1000.0f, 1.5f) << x << " " << y;
}

TEST(ShadowPresets, PresetBKeepsTheShadowsAndClearsTheBackground) {
  const std::vector<std::pair<int, int>> shadows{{40, 40}, {128, 96}, {220, 150}};
  ImageChain chain(read_chain("shadow-b"));
  const Image& out = chain.run(shadow_image(0.01, 0.3, shadows, 7), Exposure::A);
  // A 30 % shadow is 300 counts deep after normalising to 1000; the clips take ~2 sigma + 10.
  for (const auto& [x, y] : shadows) EXPECT_GT(out.at<float>(x, y), 200.0f) << x << " " << y;
  int lit = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      bool near_shadow = false;
      for (const auto& [sx, sy] : shadows) near_shadow |= std::abs(x - sx) <= 3 && std::abs(y - sy) <= 3;
      if (!near_shadow && out.at<float>(x, y) > 0) ++lit;
    }
  // Noise of 1 % beyond 2 sigma + 10 counts (3 sigma): ~0.1 % of the background at most.
  EXPECT_LT(lit, kW * kH / 200) << lit;
}

TEST(ShadowPresets, PresetASubtractsTwoSigmaOfTheNoiseFromTheInvertedShadows) {
  // 1 % noise: sigma 10 counts of the bright field at 1000; a 30 % shadow is 300 deep.
  const std::vector<std::pair<int, int>> shadows{{60, 60}, {180, 120}};
  ImageChain chain(read_chain("shadow-a"));
  const Image& out = chain.run(shadow_image(0.01, 0.3, shadows, 11), Exposure::A);
  for (const auto& [x, y] : shadows) EXPECT_NEAR(out.at<float>(x, y), 300.0f - 20.0f, 25.0f) << x << " " << y;
  int lit = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) lit += out.at<float>(x, y) > 0;
  // Beyond 2 sigma of Gaussian noise: 2.3 % of the pixels, the shadows' 26 more.
  EXPECT_GT(lit, kW * kH / 100);
  EXPECT_LT(lit, kW * kH * 4 / 100);
}

TEST(ShadowPresets, LocalNormalizeRejectsABadTileAndSizeWithOtherModes) {
  EXPECT_THROW(parse_chain("[[preprocess.steps]]\nkind = \"normalize\"\nby = \"local\"\nsize = 4\n", "t.toml"), Error);
  EXPECT_THROW(parse_chain("[[preprocess.steps]]\nkind = \"normalize\"\nby = \"mean\"\nsize = 64\n", "t.toml"), Error);
  const ChainSpec ok = parse_chain("[[preprocess.steps]]\nkind = \"normalize\"\nby = \"local\"\n", "t.toml");
  EXPECT_EQ(ok.steps[0].size, kLocalNormalizeTile);
}

}  // namespace
}  // namespace tomorig::preprocess
