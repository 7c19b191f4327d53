// Small pictures for the preview stream: thumbnails keep particle images, histograms show the
// saturated bin in their last column, captions widen the picture for their text.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/display.h"

namespace tomorig::quicklook {
namespace {

TEST(Thumbnail, KeepsALonePixelParticleAndFitsTheSize) {
  Image frame = Image::allocate(1000, 500, SampleType::u16);
  std::uint32_t state = 1;
  for (int y = 0; y < 500; ++y)
    for (int x = 0; x < 1000; ++x) {
      state = state * 1664525u + 1013904223u;
      frame.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(100 + (state >> 24) % 50);  // noisy background
    }
  frame.at<std::uint16_t>(613, 271) = 4000;  // one bright pixel: a 7 x 7 block average would lose it
  const Image t = thumbnail(frame, 160);
  EXPECT_EQ(t.type(), SampleType::u8);
  EXPECT_LE(std::max(t.width(), t.height()), 160);
  EXPECT_EQ(t.width(), 143);  // blocks of 7: ceil(1000 / 7)
  EXPECT_EQ(t.at<std::uint8_t>(613 / 7, 271 / 7), 255);
  EXPECT_THROW(thumbnail(Image(), 160), Error);
  EXPECT_THROW(thumbnail(frame, 0), Error);
}

TEST(HistogramImage, LogBarsAndTheSaturatedBinInTheLastColumn) {
  std::vector<std::uint32_t> counts(256, 0);
  counts[10] = 100000;
  counts[11] = 10;
  counts[255] = 3;  // saturated pixels
  const Image h = histogram_image(counts, 256, 64);
  auto bar = [&](int x) {
    int n = 0;
    for (int y = 0; y < 64; ++y) n += h.at<std::uint8_t>(x, y) == 255;
    return n;
  };
  EXPECT_EQ(bar(10), 64);
  EXPECT_GT(bar(11), 0);
  EXPECT_LT(bar(11), bar(10));
  EXPECT_EQ(bar(12), 0);
  EXPECT_GT(bar(255), 0) << "three saturated pixels still show";
  const Image narrow = histogram_image(counts, 32, 16);
  EXPECT_EQ(narrow.width(), 32);
  EXPECT_THROW(histogram_image(counts, 0, 10), Error);
}

TEST(Caption, TextUnderThePictureWidensItWhenNeeded) {
  Image picture = Image::allocate(20, 10, SampleType::u8);
  picture.at<std::uint8_t>(3, 4) = 77;
  const std::array<std::string, 2> lines = {"cam0 green", "ppp 0.049  d_tau 2.91  Ns 0.33"};
  const Image c = with_caption(picture, lines);
  EXPECT_GT(c.width(), 20);
  EXPECT_GT(c.height(), 10 + 2 * 10);
  EXPECT_EQ(c.at<std::uint8_t>(3, 4), 77) << "the picture is kept as it was";
  int lit = 0;
  for (int y = 10; y < c.height(); ++y)
    for (int x = 0; x < c.width(); ++x) lit += c.at<std::uint8_t>(x, y) > 128;
  EXPECT_GT(lit, 50) << "the text is drawn";
  EXPECT_THROW(with_caption(Image::allocate(4, 4, SampleType::f32), lines), Error);
}

}  // namespace
}  // namespace tomorig::quicklook
