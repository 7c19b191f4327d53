// [quicklook] keys: absent keys stay unset (the quick-look library keeps its defaults), present
// ones are read, and bad values are named by key path and line.
#include <gtest/gtest.h>

#include <algorithm>

#include "config_test_support.h"
#include "tomorig/config/rig_config.h"

namespace tomorig::config {
namespace {
using test_support::dump;
using test_support::line_containing;

std::string rig_with(const std::string& tail) {
  return "[[cameras]]\nid = \"a\"\nbackend = \"simulated\"\n[cameras.roi]\nwidth = 64\nheight = 48\n" + tail;
}

TEST(QuickLookConfig, AbsentKeysStayUnset) {
  const RigConfig rig = parse_rig_config(rig_with(""));
  EXPECT_FALSE(rig.quicklook.tile_px);
  EXPECT_FALSE(rig.quicklook.detail_tiles);
  EXPECT_FALSE(rig.quicklook.ppp);
  EXPECT_FALSE(rig.quicklook.dt_check.displacement_px);
  EXPECT_FALSE(rig.quicklook.drift.warn_px);
  EXPECT_FALSE(rig.quicklook.preview.algorithm);
  EXPECT_FALSE(rig.quicklook.spray.coverage_max);
  EXPECT_FALSE(rig.quicklook.spray.shadow_count);
  EXPECT_FALSE(rig.quicklook.spray.binning);
  // The default rig leaves them to the library too.
  const RigConfig def = default_rig_config();
  EXPECT_FALSE(def.quicklook.ppp);
  EXPECT_FALSE(def.quicklook.preview.binning);
}

TEST(QuickLookConfig, EveryKeyIsRead) {
  const RigConfig rig = parse_rig_config(rig_with(R"(
[quicklook]
tile_px = 32
detail_tiles = 64
peak_sigmas = 4.5
ppp = [0.01, 0.05]
diameter_px = [2.5, 3.5]
source_density_max = 0.25
saturated_fraction_max = 0.002
energy_balance = [0.8, 1.2]
soft_tile_fraction_max = 0.2
[quicklook.dt_check]
window_px = 48
windows = [3, 2]
min_peak_ratio = 2
displacement_px = [2, 8]
valid_fraction_min = 0.7
[quicklook.drift]
warn_px = 0.25
window_sets = 20
subvolumes = [4, 4, 2]
search_radius_px = 1.5
[quicklook.preview]
algorithm = "ment"
binning = 4
depth_factor = 1.5
mlos_threshold = 0.1
ment_iterations = 3
)"));
  const QuickLookConfig& q = rig.quicklook;
  EXPECT_EQ(q.tile_px, 32);
  EXPECT_EQ(q.detail_tiles, 64);
  EXPECT_EQ(q.peak_sigmas, 4.5);
  EXPECT_EQ(q.ppp, (std::array<double, 2>{0.01, 0.05}));
  EXPECT_EQ(q.diameter_px, (std::array<double, 2>{2.5, 3.5}));
  EXPECT_EQ(q.source_density_max, 0.25);
  EXPECT_EQ(q.saturated_fraction_max, 0.002);
  EXPECT_EQ(q.energy_balance, (std::array<double, 2>{0.8, 1.2}));
  EXPECT_EQ(q.soft_tile_fraction_max, 0.2);
  EXPECT_EQ(q.dt_check.window_px, 48);
  EXPECT_EQ(q.dt_check.windows, (std::array<int, 2>{3, 2}));
  EXPECT_EQ(q.dt_check.min_peak_ratio, 2.0);
  EXPECT_EQ(q.dt_check.displacement_px, (std::array<double, 2>{2, 8}));
  EXPECT_EQ(q.dt_check.valid_fraction_min, 0.7);
  EXPECT_EQ(q.drift.warn_px, 0.25);
  EXPECT_EQ(q.drift.window_sets, 20);
  EXPECT_EQ(q.drift.subvolumes, (std::array<int, 3>{4, 4, 2}));
  EXPECT_EQ(q.drift.search_radius_px, 1.5);
  EXPECT_EQ(q.preview.algorithm, "ment");
  EXPECT_EQ(q.preview.binning, 4);
  EXPECT_EQ(q.preview.depth_factor, 1.5);
  EXPECT_EQ(q.preview.mlos_threshold, 0.1);
  EXPECT_EQ(q.preview.ment_iterations, 3);
}

TEST(QuickLookConfig, EverySprayKeyIsRead) {
  const RigConfig rig = parse_rig_config(rig_with(R"(
[quicklook.spray]
coverage_max = 0.08
uniformity_min = 0.6
energy_tolerance = 0.15
bright_fraction = [0.04, 0.8]
shadow_count = [200, 1500]
min_intensity_max = 0.4
binning = 2
shadow_sigmas = 5
reference_sets = 20
)"));
  const QuickLookConfig::Spray& q = rig.quicklook.spray;
  EXPECT_EQ(q.coverage_max, 0.08);
  EXPECT_EQ(q.uniformity_min, 0.6);
  EXPECT_EQ(q.energy_tolerance, 0.15);
  EXPECT_EQ(q.bright_fraction, (std::array<double, 2>{0.04, 0.8}));
  EXPECT_EQ(q.shadow_count, (std::array<double, 2>{200, 1500}));
  EXPECT_EQ(q.min_intensity_max, 0.4);
  EXPECT_EQ(q.binning, 2);
  EXPECT_EQ(q.shadow_sigmas, 5.0);
  EXPECT_EQ(q.reference_sets, 20);
}

void expect_issue(const std::string& tail, const std::string& key, const std::string& at, const std::string& text) {
  const std::string doc = rig_with(tail);
  const auto issues = check_rig_config(doc, "rig.toml");
  const auto it = std::find_if(issues.begin(), issues.end(), [&](const ConfigIssue& i) { return i.key == key; });
  ASSERT_NE(it, issues.end()) << "no issue for " << key << "; got:\n" << dump(issues);
  EXPECT_EQ(it->line, line_containing(doc, at)) << it->to_string();
  EXPECT_NE(it->message.find(text), std::string::npos) << it->to_string() << "\nwanted: " << text;
}

TEST(QuickLookConfig, BadValuesAreNamed) {
  expect_issue("[quicklook]\nppp = [0.08, 0.02]\n", "quicklook.ppp", "ppp =", "low <= high");
  expect_issue("[quicklook]\ntile_px = 4\n", "quicklook.tile_px", "tile_px", "must be in [8, 1024]");
  expect_issue("[quicklook]\ndetail_tiles = 0\n", "quicklook.detail_tiles", "detail_tiles", "must be in [1, 65536]");
  expect_issue("[quicklook]\nsaturated_fraction_max = 2\n", "quicklook.saturated_fraction_max", "saturated",
               "must be in (0, 1]");
  expect_issue("[quicklook.dt_check]\nwindows = [4, 2.5]\n", "quicklook.dt_check.windows", "windows",
               "whole number from 1 to 64");
  expect_issue("[quicklook.drift]\nsubvolumes = [5, 5]\n", "quicklook.drift.subvolumes", "subvolumes",
               "expected an array of 3 numbers");
  expect_issue("[quicklook.preview]\nalgorithm = \"fmart\"\n", "quicklook.preview.algorithm", "algorithm",
               "must be one of mlos, ment");
  expect_issue("[quicklook.drift]\nwarn = 0.3\n", "quicklook.drift.warn", "warn =", "did you mean \"warn_px\"?");
  expect_issue("[quicklook]\nppp_range = [0.1, 0.2]\n", "quicklook.ppp_range", "ppp_range", "unknown key");
  expect_issue("[quicklook.spray]\ncoverage_max = 0\n", "quicklook.spray.coverage_max", "coverage_max", "must be in (0, 1]");
  expect_issue("[quicklook.spray]\nenergy_tolerance = 1.2\n", "quicklook.spray.energy_tolerance", "energy_tolerance",
               "must be in (0, 1)");
  expect_issue("[quicklook.spray]\nbright_fraction = [0.1, 1.5]\n", "quicklook.spray.bright_fraction", "bright_fraction",
               "at most 1");
  expect_issue("[quicklook.spray]\nshadow_count = [900, 100]\n", "quicklook.spray.shadow_count", "shadow_count",
               "low <= high");
  expect_issue("[quicklook.spray]\nbinning = 12\n", "quicklook.spray.binning", "binning", "must be in [0, 8]");
  expect_issue("[quicklook.spray]\nshadow_sigmas = 0.5\n", "quicklook.spray.shadow_sigmas", "shadow_sigmas",
               "must be in [1, 50]");
  expect_issue("[quicklook.spray]\nenergy_balance = [0.9, 1.1]\n", "quicklook.spray.energy_balance", "energy_balance",
               "unknown key");
}

}  // namespace
}  // namespace tomorig::config
