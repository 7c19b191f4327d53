// Each preprocessing step on an input whose correct output is known by construction.
#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/preprocess/image_chain.h"
#include "tomorig/processing/preprocess/sequence_image.h"

namespace tomorig::preprocess {
namespace {

constexpr int kW = 48, kH = 40;

Image constant_u16(std::uint16_t value, int w = kW, int h = kH) {
  Image image = Image::allocate(w, h, SampleType::u16);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.at<std::uint16_t>(x, y) = value;
  return image;
}

Image constant_f32(float value, int w = kW, int h = kH) {
  Image image = Image::allocate(w, h, SampleType::f32);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) image.at<float>(x, y) = value;
  return image;
}

ImageChain chain_of(Step step) { return ImageChain(ChainSpec{{step}}); }

Step step_of(StepKind kind) {
  Step s;
  s.kind = kind;
  return s;
}

TEST(PreprocessSteps, LocalMinimumRemovesBackgroundAndKeepsSpots) {
  Image in = constant_u16(300);
  in.at<std::uint16_t>(10, 10) = 1300;  // a single-pixel spot
  for (int y = 20; y < 22; ++y)
    for (int x = 30; x < 32; ++x) in.at<std::uint16_t>(x, y) = 800;  // a 2 x 2 spot
  Step s = step_of(StepKind::subtract_local_minimum);
  s.size = 5;
  ImageChain chain = chain_of(s);
  const Image& out = chain.run(in, Exposure::A);
  EXPECT_FLOAT_EQ(out.at<float>(10, 10), 1000.0f);
  EXPECT_FLOAT_EQ(out.at<float>(30, 20), 500.0f);
  EXPECT_FLOAT_EQ(out.at<float>(31, 21), 500.0f);
  EXPECT_FLOAT_EQ(out.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(out.at<float>(40, 5), 0.0f);
}

TEST(PreprocessSteps, MedianRemovesAHotPixel) {
  Image in = constant_u16(100);
  in.at<std::uint16_t>(7, 9) = 60000;
  ImageChain chain = chain_of(step_of(StepKind::median));
  const Image& out = chain.run(in, Exposure::A);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_FLOAT_EQ(out.at<float>(x, y), 100.0f) << x << "," << y;
}

TEST(PreprocessSteps, StreamingMinimumEqualsPixelwiseMinimum) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> value(0, 4000);
  std::vector<Image> frames;
  MinimumImage minimum;
  for (int k = 0; k < 3; ++k) {
    Image f = Image::allocate(kW, kH, SampleType::u16);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) f.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(value(rng));
    minimum.add(f);
    frames.push_back(f);
  }
  EXPECT_EQ(minimum.count(), 3u);
  const Image& m = minimum.result();
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double expected = std::min({frames[0].value(x, y), frames[1].value(x, y), frames[2].value(x, y)});
      ASSERT_EQ(m.value(x, y), expected);
    }

  // And the chain subtracts it: frame 0 minus the minimum is >= 0 and 0 where frame 0 is the minimum.
  ImageChain chain = chain_of(step_of(StepKind::subtract_minimum));
  chain.set_sequence_image(0, Exposure::B, m);
  const Image& out = chain.run(frames[0], Exposure::B);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_FLOAT_EQ(out.at<float>(x, y), static_cast<float>(frames[0].value(x, y) - m.value(x, y)));
  // Exposure A has no minimum: a clear error, not a silent pass-through.
  EXPECT_THROW(chain.run(frames[0], Exposure::A), Error);
}

TEST(PreprocessSteps, MinimumImageRefusesAFrameOfAnotherSize) {
  MinimumImage minimum;
  minimum.add(constant_u16(1));
  EXPECT_THROW(minimum.add(constant_u16(1, kW + 1, kH)), Error);
  MinimumImage empty;
  EXPECT_THROW(empty.result(), Error);
}

TEST(PreprocessSteps, MeanImageIsThePixelwiseAverage) {
  MeanImage mean;
  mean.add(constant_u16(100));
  mean.add(constant_u16(300));
  EXPECT_FLOAT_EQ(mean.result().at<float>(3, 4), 200.0f);
}

TEST(PreprocessSteps, FlatFieldOfAKnownGradientIsFlat) {
  // A uniform scene of 500 seen through a vignetting gain g(x) = 0.5 + x / W; the bright
  // field is the same gain times 2000. Division leaves 500 * mean(bright) / 2000 everywhere.
  Image bright = Image::allocate(kW, kH, SampleType::f32);
  Image in = Image::allocate(kW, kH, SampleType::f32);
  double bright_sum = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double gain = 0.5 + static_cast<double>(x) / kW;
      bright.at<float>(x, y) = static_cast<float>(2000 * gain);
      in.at<float>(x, y) = static_cast<float>(500 * gain);
      bright_sum += 2000 * gain;
    }
  const double bright_mean = bright_sum / (kW * kH);
  Step s = step_of(StepKind::flat_field);
  s.file = "bright.h5";
  ImageChain chain = chain_of(s);
  chain.set_reference_image(0, bright);
  const Image& out = chain.run(in, Exposure::A);
  const double expected = 500.0 / 2000.0 * bright_mean;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) ASSERT_NEAR(out.at<float>(x, y), expected, 1e-3 * expected) << x;
}

TEST(PreprocessSteps, DarkSubtractionAndInversion) {
  Step dark = step_of(StepKind::subtract_dark);
  dark.level = 50;
  Step invert = step_of(StepKind::invert);
  invert.max = 4095;
  ImageChain chain(ChainSpec{{dark, invert}});
  Image in = constant_u16(1050);
  in.at<std::uint16_t>(1, 1) = 20;  // below the dark level: clipped to 0, inverted to 4095
  const Image& out = chain.run(in, Exposure::A);
  EXPECT_FLOAT_EQ(out.at<float>(0, 0), 4095.0f - 1000.0f);
  EXPECT_FLOAT_EQ(out.at<float>(1, 1), 4095.0f);

  Step dark_file = step_of(StepKind::subtract_dark);
  dark_file.file = "dark.h5";
  ImageChain per_pixel = chain_of(dark_file);
  Image dark_image = constant_f32(30);
  dark_image.at<float>(2, 3) = 90;
  per_pixel.set_reference_image(0, dark_image);
  const Image& d = per_pixel.run(constant_u16(100), Exposure::B);
  EXPECT_FLOAT_EQ(d.at<float>(0, 0), 70.0f);
  EXPECT_FLOAT_EQ(d.at<float>(2, 3), 10.0f);
  // A dark image of another size is refused with the step named.
  ImageChain wrong = chain_of(dark_file);
  wrong.set_reference_image(0, constant_f32(30, kW, kH + 2));
  try {
    wrong.run(constant_u16(100), Exposure::A);
    FAIL() << "a dark image of the wrong size was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("subtract_dark"), std::string::npos) << e.what();
  }
}

TEST(PreprocessSteps, HighPassRemovesASmoothBackgroundLowPassKeepsIt) {
  Image in = Image::allocate(kW, kH, SampleType::f32);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) in.at<float>(x, y) = 200.0f + 2.0f * static_cast<float>(x);  // linear ramp
  in.at<float>(24, 20) += 1000.0f;
  Step high = step_of(StepKind::highpass);
  high.sigma = 2.0;
  ImageChain hp = chain_of(high);
  const Image& h = hp.run(in, Exposure::A);
  // A linear ramp is unchanged by a symmetric blur, so away from the spot and the borders the
  // high pass is ~0, and the spot keeps most of its height.
  EXPECT_NEAR(h.at<float>(10, 10), 0.0f, 0.5f);
  EXPECT_GT(h.at<float>(24, 20), 900.0f);
  Step low = step_of(StepKind::lowpass);
  low.sigma = 2.0;
  ImageChain lp = chain_of(low);
  const Image& l = lp.run(in, Exposure::A);
  EXPECT_NEAR(l.at<float>(10, 10), 220.0f, 0.5f);
  EXPECT_LT(l.at<float>(24, 20), 300.0f);  // the spot is spread out
}

TEST(PreprocessSteps, NormalizeByMeanAndByAverageImage) {
  Step by_mean = step_of(StepKind::normalize);
  by_mean.target = 1000;
  ImageChain chain = chain_of(by_mean);
  Image in = constant_u16(250);
  in.at<std::uint16_t>(0, 0) = 500;
  const Image& out = chain.run(in, Exposure::A);
  const double mean = (250.0 * (kW * kH - 1) + 500.0) / (kW * kH);
  EXPECT_NEAR(out.at<float>(5, 5), 250.0 / mean * 1000.0, 1e-3);

  Step by_average = by_mean;
  by_average.by = NormalizeBy::average_image;
  ImageChain avg = chain_of(by_average);
  Image average = constant_f32(125);
  average.at<float>(1, 1) = 0;  // no light there: 0, not infinity
  avg.set_sequence_image(0, Exposure::A, average);
  const Image& a = avg.run(constant_u16(250), Exposure::A);
  EXPECT_FLOAT_EQ(a.at<float>(5, 5), 2000.0f);
  EXPECT_FLOAT_EQ(a.at<float>(1, 1), 0.0f);
}

TEST(PreprocessSteps, ClipAtKSigmaOfAKnownNoiseBackground) {
  constexpr int w = 200, h = 200;
  Image in = Image::allocate(w, h, SampleType::f32);
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(100.0f, 5.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) in.at<float>(x, y) = noise(rng);
  for (int k = 0; k < 50; ++k) in.at<float>(4 * k, 2 * k) = 1000.0f;  // spots
  Step clip = step_of(StepKind::clip);
  clip.use_sigmas = true;
  clip.sigmas = 4.0;
  ImageChain chain = chain_of(clip);
  const Image& out = chain.run(in, Exposure::A);
  int kept_background = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool spot = y % 2 == 0 && x == 2 * y && y < 100;  // the spots at (4k, 2k)
      if (spot) ASSERT_FLOAT_EQ(out.at<float>(x, y), 1000.0f);
      else if (out.at<float>(x, y) != 0.0f) ++kept_background;
    }
  // Above 4 sigma of Gaussian noise: 3e-5 of 40000 pixels, ~1; a threshold at the mean would keep half.
  EXPECT_LE(kept_background, 10);

  // A constant level with subtraction: the offset of thesis Sect. 6.5.
  Step offset = step_of(StepKind::clip);
  offset.level = 200;
  offset.subtract = true;
  ImageChain sub = chain_of(offset);
  Image spots = constant_u16(150);
  spots.at<std::uint16_t>(3, 3) = 700;
  const Image& o = sub.run(spots, Exposure::A);
  EXPECT_FLOAT_EQ(o.at<float>(0, 0), 0.0f);
  EXPECT_FLOAT_EQ(o.at<float>(3, 3), 500.0f);
}

TEST(PreprocessSteps, ToUint16RoundsAndClips) {
  Image f = constant_f32(0);
  f.at<float>(0, 0) = -5.0f;
  f.at<float>(1, 0) = 12.5f;
  f.at<float>(2, 0) = 12.4f;
  f.at<float>(3, 0) = 1e6f;
  f.at<float>(4, 0) = std::nanf("");
  Image out;
  to_uint16(f, out);
  EXPECT_EQ(out.at<std::uint16_t>(0, 0), 0);
  EXPECT_EQ(out.at<std::uint16_t>(1, 0), 13);
  EXPECT_EQ(out.at<std::uint16_t>(2, 0), 12);
  EXPECT_EQ(out.at<std::uint16_t>(3, 0), 65535);
  EXPECT_EQ(out.at<std::uint16_t>(4, 0), 0);
}

TEST(PreprocessSteps, BadParametersNameTheStepAndParameter) {
  Step s = step_of(StepKind::subtract_local_minimum);
  s.size = 1;
  try {
    ImageChain chain = chain_of(s);
    FAIL() << "a local-minimum size of 1 was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("subtract_local_minimum"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("size"), std::string::npos) << e.what();
  }
  Step g = step_of(StepKind::lowpass);
  g.sigma = 0;
  EXPECT_THROW(chain_of(g), Error);
  Step m = step_of(StepKind::median);
  m.size = 7;
  EXPECT_THROW(chain_of(m), Error);
}

TEST(PreprocessSteps, BuffersAreReusedAcrossFrames) {
  Step s = step_of(StepKind::median);
  ImageChain chain = chain_of(s);
  const std::byte* first = chain.run(constant_u16(10), Exposure::A).data();
  const std::byte* second_run = chain.run(constant_u16(20), Exposure::A).data();
  const std::byte* third_run = chain.run(constant_u16(30), Exposure::A).data();
  // The median swaps two buffers: frames alternate between the same two allocations.
  EXPECT_EQ(first, third_run);
  EXPECT_NE(first, second_run);
}

}  // namespace
}  // namespace tomorig::preprocess
