// The sensor: rounding, saturation and noise statistics.
#include <cmath>

#include <gtest/gtest.h>

#include "tomorig/core/error.h"
#include "tomorig/simulators/sensor.h"

namespace {

using tomorig::Image;
using tomorig::SampleType;
using tomorig::sim::SensorOptions;

Image flat(int w, int h, float value) {
  Image img = Image::allocate(w, h, SampleType::f32);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at<float>(x, y) = value;
  return img;
}

TEST(Sensor, NoiseFreeRoundsAndSaturatesAt12Bit) {
  Image signal = flat(4, 1, 0);
  signal.at<float>(0, 0) = 12.4f;
  signal.at<float>(1, 0) = 12.6f;
  signal.at<float>(2, 0) = 5000.0f;
  signal.at<float>(3, 0) = -3.0f;
  SensorOptions opt;
  opt.bit_depth = 12;
  const Image out = tomorig::sim::digitise(signal, opt, 1);
  EXPECT_EQ(out.type(), SampleType::u16);
  EXPECT_EQ(out.at<std::uint16_t>(0, 0), 12);
  EXPECT_EQ(out.at<std::uint16_t>(1, 0), 13);
  EXPECT_EQ(out.at<std::uint16_t>(2, 0), 4095);
  EXPECT_EQ(out.at<std::uint16_t>(3, 0), 0);
  opt.bit_depth = 16;
  signal.at<float>(2, 0) = 1e6f;
  EXPECT_EQ(tomorig::sim::digitise(signal, opt, 1).at<std::uint16_t>(2, 0), 65535);
}

TEST(Sensor, NoiseHasTheExpectedMeanAndVariance) {
  // Flat 1000 counts at 2 counts/e-: shot variance gain * S = 2000 counts^2, read noise 5 e-
  // = 10 counts -> 100 counts^2; rounding adds 1/12.
  const Image signal = flat(256, 256, 1000.0f);
  SensorOptions opt;
  opt.noise = true;
  opt.gain_counts_per_e = 2.0;
  opt.read_noise_e = 5.0;
  const Image out = tomorig::sim::digitise(signal, opt, 99);
  double sum = 0, sum2 = 0;
  const double n = 256.0 * 256.0;
  for (int y = 0; y < 256; ++y)
    for (int x = 0; x < 256; ++x) {
      const double v = out.value(x, y);
      sum += v;
      sum2 += v * v;
    }
  const double mean = sum / n, variance = sum2 / n - mean * mean;
  EXPECT_NEAR(mean, 1000.0, 1.0);
  EXPECT_NEAR(variance / (2000.0 + 100.0 + 1.0 / 12), 1.0, 0.03);
}

TEST(Sensor, NoiseIsSeededAndThreadIndependent) {
  const Image signal = flat(64, 64, 300.0f);
  SensorOptions opt;
  opt.noise = true;
  opt.threads = 1;
  const Image a = tomorig::sim::digitise(signal, opt, 5);
  opt.threads = 3;
  EXPECT_TRUE(a.same_pixels(tomorig::sim::digitise(signal, opt, 5)));
  EXPECT_FALSE(a.same_pixels(tomorig::sim::digitise(signal, opt, 6)));
}

TEST(Sensor, RejectsUnsupportedBitDepth) {
  SensorOptions opt;
  opt.bit_depth = 10;
  EXPECT_THROW(tomorig::sim::digitise(flat(2, 2, 0), opt, 1), tomorig::Error);
}

}  // namespace
