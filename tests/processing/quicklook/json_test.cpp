// JSON form of the quick-look results: the fields a preview client reads, null for what could
// not be measured, flags as words.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "particle_field.h"
#include "tomorig/processing/quicklook/json.h"

namespace tomorig::quicklook {
namespace {

TEST(QuickLookJson, CameraStatisticsCarryEveryFigureAndItsFlag) {
  testing::FieldSpec spec;
  spec.ppp = 0.04;
  spec.sigma_px = 0.625;
  const Image a = testing::make_field(spec).image;
  spec.seed = 2;
  const Image b = testing::make_field(spec).image;
  QuickLook ql;
  CameraQuickLook s;
  ql.analyse(a, b, s);
  const nlohmann::json j = s;
  const nlohmann::json back = nlohmann::json::parse(j.dump());  // survives text
  EXPECT_EQ(back["flag"], "green");
  EXPECT_EQ(back["energy_balance"]["flag"], "green");
  EXPECT_DOUBLE_EQ(back["energy_balance"]["value"].get<double>(), s.energy_balance.value);
  const auto& frame = back["a"];
  EXPECT_EQ(frame["width"], 512);
  EXPECT_EQ(frame["full_scale"], 65535);
  EXPECT_DOUBLE_EQ(frame["particles"]["ppp"]["value"].get<double>(), s.a.ppp.value);
  EXPECT_EQ(frame["particles"]["ppp"]["flag"], "green");
  EXPECT_DOUBLE_EQ(frame["particles"]["diameter_px"]["value"].get<double>(), s.a.diameter_px.value);
  EXPECT_DOUBLE_EQ(frame["particles"]["source_density"]["value"].get<double>(), s.a.source_density.value);
  EXPECT_DOUBLE_EQ(frame["particles"]["maxima_per_pixel"].get<double>(), s.a.maxima_per_pixel);
  EXPECT_DOUBLE_EQ(frame["background"]["level"].get<double>(), s.a.background);
  EXPECT_DOUBLE_EQ(frame["background"]["noise"].get<double>(), s.a.noise);
  EXPECT_EQ(frame["background"]["map"]["values"].size(), 64u);
  EXPECT_EQ(frame["saturation"]["map"]["tiles_x"], 8);
  EXPECT_EQ(frame["saturation"]["fraction"]["flag"], "green");
  EXPECT_EQ(frame["histogram"]["counts"].size(), 256u);
  EXPECT_DOUBLE_EQ(frame["histogram"]["bin_width"].get<double>(), 256.0);
  EXPECT_EQ(frame["focus"]["map"]["values"].size(), 64u);
  EXPECT_TRUE(frame["percentiles"].contains("p99.9"));
}

TEST(QuickLookJson, WhatCannotBeMeasuredIsNull) {
  testing::FieldSpec spec;
  spec.ppp = 1e-9;  // no particles
  QuickLook ql;
  FrameStatistics s;
  ql.analyse(testing::make_field(spec).image, s);
  const nlohmann::json j = nlohmann::json::parse(nlohmann::json(s).dump());
  EXPECT_TRUE(j["particles"]["diameter_px"]["value"].is_null());
  EXPECT_EQ(j["particles"]["diameter_px"]["flag"], "red");
  EXPECT_TRUE(j["particles"]["source_density"]["value"].is_null());
  EXPECT_TRUE(j["focus"]["map"]["values"][0].is_null());
  EXPECT_EQ(j["flag"], "red");
}

TEST(QuickLookJson, DtCheckResult) {
  testing::FieldSpec spec;
  auto particles = testing::random_particles(spec);
  const Image a = testing::digitise(testing::render(particles, spec), spec, 1);
  for (auto& p : particles) p.centre.x += 5.0;
  const Image b = testing::digitise(testing::render(particles, spec), spec, 2);
  DtCheck check;
  DtCheckResult r;
  check.check(a, b, r);
  const nlohmann::json j = nlohmann::json::parse(nlohmann::json(r).dump());
  EXPECT_EQ(j["flag"], "green");
  EXPECT_EQ(j["windows"].size(), 16u);
  EXPECT_NEAR(j["displacement_px"]["value"].get<double>(), 5.0, 0.1);
  EXPECT_NEAR(j["median_dx"].get<double>(), 5.0, 0.1);
  EXPECT_EQ(j["displacement_histogram"].size(), 32u);
  EXPECT_TRUE(j["windows"][0]["valid"].get<bool>());
}

TEST(QuickLookJson, SheetProfile) {
  // Ghost 0.25 around a flat sheet over slices 10 to 19, one slice nobody sees.
  std::vector<double> p(40, 0.5);
  for (int k = 10; k < 20; ++k) p[static_cast<std::size_t>(k)] = 2.0;
  p[39] = std::nan("");
  const SheetProfile s = analyse_depth_profile(p, -2.0, 0.1);
  const nlohmann::json j = nlohmann::json::parse(nlohmann::json(s).dump());
  EXPECT_TRUE(j["found"].get<bool>());
  EXPECT_NEAR(j["thickness_mm"].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j["position_mm"].get<double>(), -2.0 + 1.45, 1e-9);
  EXPECT_NEAR(j["ghost_front"].get<double>(), 0.25, 1e-9);
  EXPECT_NEAR(j["rsnr"].get<double>(), 4.0, 1e-9);
  EXPECT_EQ(j["flag"], "green");
  EXPECT_DOUBLE_EQ(j["z0_mm"].get<double>(), -2.0);
  EXPECT_NEAR(j["dz_mm"].get<double>(), 0.1, 1e-12);
  ASSERT_EQ(j["profile"].size(), 40u);
  EXPECT_DOUBLE_EQ(j["profile"][10].get<double>(), 1.0);
  EXPECT_TRUE(j["profile"][39].is_null());

  PreviewResult r;
  r.grid = VoxelGrid::centred(4, 5, 40, 0.1);
  r.sheet = s;
  r.active_voxels = 7;
  const nlohmann::json pr = nlohmann::json::parse(nlohmann::json(r).dump());
  EXPECT_EQ(pr["grid"]["ny"], 5);
  EXPECT_EQ(pr["active_voxels"], 7);
  EXPECT_EQ(pr["sheet"]["profile"].size(), 40u);
}

}  // namespace
}  // namespace tomorig::quicklook
