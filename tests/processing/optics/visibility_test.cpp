// The smallest visible droplet (thesis Sect. 6.4, 7.3.3): the search against Eq. 6.6 itself and
// its closed form for an opaque droplet, the set-up limit as the largest of the cameras', the
// thesis's in-focus figure, and the bright-field noise estimate against a known noise.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/processing/optics/droplet_image.h"
#include "tomorig/processing/optics/visibility.h"

namespace tomorig::optics {
namespace {

TEST(Visibility, SmallestVisibleDropletIsTheFirstCrossingOfTheThreshold) {
  const TransmissionModel model(Liquid::kerosene(), LedSpectrum{});
  const TransmissionTable table(model, object_numerical_aperture(22, 0.9), 100.0);
  for (double chi : {20.0, 45.0, 80.0}) {
    const double thr = 0.98;
    const double d = smallest_visible_diameter(table, chi, thr);
    ASSERT_TRUE(std::isfinite(d)) << chi;
    EXPECT_LE(minimum_intensity(d, chi, table.tau(d)), thr);
    for (double smaller = 0.05; smaller < d - 0.02; smaller += 0.05)
      ASSERT_GT(minimum_intensity(smaller, chi, table.tau(smaller)), thr) << "chi " << chi << " d " << smaller;
    // An opaque droplet (tau = 0) reaches it at d = sqrt2 chi sqrt(-ln thr); light that still
    // reaches the lens only makes it harder.
    EXPECT_GE(d, std::sqrt(2.0) * chi * std::sqrt(-std::log(thr)) - 0.01);
  }
  // A threshold no shadow reaches: none visible.
  EXPECT_EQ(smallest_visible_diameter(table, 45.0, 0.3), kNotVisible);
}

TEST(Visibility, InFocusLimitOfTheThesisFeasibilityStudy) {
  // Sect. 6.4: water spray, f# 22 at M ~ 0.45, chi ~ 44 um in focus at 60 voxel/mm; the
  // set-up's limit "reduces to d_min = 8 um". The thesis does not print its threshold for that
  // study; with Ch. 7's 0.980 the model gives the same size to within a micrometre.
  VisibilitySetup s;
  s.liquid = Liquid::water();
  s.spectrum = LedSpectrum{525.0, 35.0, 9};  // Sect. 6.2
  s.cameras.push_back({"view1", 22, 0.45, 0.01, {{0.0, 44.0}}});
  const std::vector<VisibilityRow> rows = visibility_table(s);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NEAR(rows[0].setup_d_min_um, 8.0, 1.0);
}

TEST(Visibility, SetupLimitIsTheLargestOfTheCameras) {
  VisibilitySetup s;
  s.cameras.push_back({"a", 22, 0.9, 0.010, {{-4.0, 80.0}, {0.0, 40.0}, {4.0, 60.0}}});
  s.cameras.push_back({"b", 22, 0.9, 0.006, {{-4.0, 50.0}, {0.0, 45.0}, {4.0, 100.0}}});
  s.d_max_um = 120;
  const std::vector<VisibilityRow> rows = visibility_table(s);
  ASSERT_EQ(rows.size(), 3u);
  for (const VisibilityRow& r : rows) {
    ASSERT_EQ(r.d_min_um.size(), 2u);
    EXPECT_EQ(r.setup_d_min_um, std::max(r.d_min_um[0], r.d_min_um[1])) << r.z_mm;
  }
  // Worse focus, bigger limit; a lower noise lowers it.
  EXPECT_GT(rows[0].d_min_um[0], rows[1].d_min_um[0]);
  EXPECT_GT(rows[2].d_min_um[1], rows[0].d_min_um[1]);
  EXPECT_DOUBLE_EQ(rows[2].chi_um[1], 100.0);
  // Between samples chi is interpolated; outside them it is unknown.
  EXPECT_DOUBLE_EQ(s.cameras[0].chi_at(2.0), 50.0);
  EXPECT_TRUE(std::isnan(s.cameras[0].chi_at(5.0)));
}

TEST(Visibility, RefusesBadSetups) {
  VisibilitySetup s;
  EXPECT_THROW(s.validate(), Error);  // no cameras
  s.cameras.push_back({"a", 22, 0.9, 0.01, {{0.0, 40.0}, {-1.0, 50.0}}});
  try {
    s.validate();
    ADD_FAILURE() << "descending z accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ascending"), std::string::npos) << e.what();
  }
  s.cameras[0].chi = {{0.0, 40.0}};
  s.cameras[0].noise_sigma = 0.0;
  EXPECT_THROW(s.validate(), Error);
}

TEST(Visibility, BrightFieldNoiseIsRecoveredDespiteUnevenLight) {
  // 20 frames of a vignetted bright field (a 40 % fall-off) with 1 % multiplicative noise.
  const int w = 64, h = 48;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<Image> frames;
  for (int k = 0; k < 20; ++k) {
    Image f = Image::allocate(w, h, SampleType::f32);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double light = 3000.0 * (1.0 - 0.4 * (x * x + y * y) / double(w * w + h * h));
        f.at<float>(x, y) = static_cast<float>(light * (1.0 + noise(rng)));
      }
    frames.push_back(std::move(f));
  }
  EXPECT_NEAR(bright_field_noise(frames), 0.01, 0.0004);
  EXPECT_THROW(bright_field_noise(std::span<const Image>(frames.data(), 1)), Error);
}

}  // namespace
}  // namespace tomorig::optics
