// Preview volume against the simulator's truth: the light sheet of the tpiv-thesis case is
// found where the case puts it and as thick as it is, whatever the grid expects; the depth
// profile's analysis on profiles of known shape; bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "tomorig/core/error.h"
#include "tomorig/processing/quicklook/preview_volume.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::quicklook {
namespace {

struct ThesisRig {
  sim::SimulatedRig rig;
  std::vector<std::shared_ptr<const calibration::CameraModel>> models;
  std::vector<calibration::ImageSize> sizes;

  explicit ThesisRig(const sim::SimulationOptions& options) : rig(options) {
    for (const sim::SimulatedCamera& c : rig.cameras()) {
      models.push_back(std::make_shared<calibration::PinholeCamera>(c.model));
      sizes.push_back({c.spec.width, c.spec.height});
    }
  }
  const VoxelGrid& grid() const { return rig.case_definition().grid; }
  std::vector<Image> exposure_a(std::uint64_t k) const {
    const sim::SimulatedSet s = rig.render_set(k);
    std::vector<Image> out;
    for (const CameraFrames& c : s.frames.cameras) out.push_back(c.a.image);
    return out;
  }
};

sim::SimulationOptions thesis(double ppp, sim::LightSheetProfile sheet, bool noise = false) {
  sim::SimulationOptions o;
  o.ppp = ppp;
  o.light_sheet = sheet;
  o.noise = noise;
  o.seed = 11;
  return o;
}

PreviewResult preview(const ThesisRig& r, const VoxelGrid& grid, const PreviewVolumeOptions& options = {}) {
  PreviewVolume pv(r.models, r.sizes, grid, options);
  PreviewResult out;
  pv.reconstruct(r.exposure_a(0), out);
  return out;
}

// The truth: the simulator's light sheet of the case.
void expect_sheet_at_truth(const PreviewResult& res, const sim::LightSheet& truth, double thickness_tolerance) {
  ASSERT_TRUE(res.sheet.found);
  const double slice = res.grid.voxel_size;
  EXPECT_NEAR(res.sheet.position_mm, truth.centre_z_mm, slice) << "within one preview slice";
  EXPECT_NEAR(res.sheet.thickness_mm, truth.thickness_mm, thickness_tolerance * truth.thickness_mm);
  EXPECT_GT(res.sheet.rsnr, 1.3);
  EXPECT_GT(res.sheet.ghost_front, 0.0);
  EXPECT_LT(res.sheet.ghost_front, 0.8);
  EXPECT_GT(res.sheet.ghost_back, 0.0);
  EXPECT_LT(res.sheet.ghost_back, 0.8);
}

TEST(PreviewVolume, FindsTheThesisSheetWhereTheLightIs) {
  const ThesisRig r(thesis(0.05, sim::LightSheetProfile::uniform));
  const PreviewResult res = preview(r, r.grid());
  // The coarse grid: binned voxels, twice the rig grid's depth, on its centre.
  EXPECT_EQ(res.grid.nx, 256);
  EXPECT_EQ(res.grid.ny, 256);
  EXPECT_EQ(res.grid.nz, 160);
  EXPECT_DOUBLE_EQ(res.grid.voxel_size, 2 * r.grid().voxel_size);
  EXPECT_NEAR(res.grid.origin.z + (res.grid.nz - 1) * 0.5 * res.grid.voxel_size, 0.0, 1e-12);
  expect_sheet_at_truth(res, r.rig.light_sheet(), 0.03);
  EXPECT_EQ(res.sheet.flag, Flag::green) << "the sheet lies inside the rig's grid";
  // Thesis Fig. 5.9: the sheet stands out of the ghost level on both sides.
  ASSERT_EQ(res.sheet.intensity.size(), static_cast<std::size_t>(res.grid.nz));
  EXPECT_NEAR(res.sheet.z_mm[80] - res.sheet.z_mm[79], res.grid.voxel_size, 1e-12);
  // Projections as big as the grid's faces, and bright where the sheet is.
  EXPECT_EQ(res.mip_z.width(), res.grid.nx);
  EXPECT_EQ(res.mip_z.height(), res.grid.ny);
  EXPECT_EQ(res.mip_y.width(), res.grid.nx);
  EXPECT_EQ(res.mip_y.height(), res.grid.nz);
  EXPECT_EQ(res.mip_x.width(), res.grid.ny);
  EXPECT_EQ(res.mip_x.height(), res.grid.nz);
  EXPECT_GT(res.active_voxels, 0u);
  EXPECT_GE(res.seconds, res.reconstruction_seconds);
}

TEST(PreviewVolume, SoftEdgedNoisySheetReadsSomewhatThin) {
  // Top-hat light with erf edges, 50 % at the slab faces; shot and read noise. MLOS's
  // light^4 narrows the soft edges (preview_volume.h): within 12 %.
  const ThesisRig r(thesis(0.05, sim::LightSheetProfile::tophat, true));
  const PreviewResult res = preview(r, r.grid());
  expect_sheet_at_truth(res, r.rig.light_sheet(), 0.12);
  EXPECT_LT(res.sheet.thickness_mm, r.rig.light_sheet().thickness_mm);
}

TEST(PreviewVolume, FindsTheSheetOffTheGridCentreAndSaysItLeavesTheGrid) {
  const ThesisRig r(thesis(0.05, sim::LightSheetProfile::uniform));
  VoxelGrid moved = r.grid();
  moved.origin.z += 0.6;  // the rig expects the light 0.6 mm deeper than it is
  const PreviewResult res = preview(r, moved);
  expect_sheet_at_truth(res, r.rig.light_sheet(), 0.03);
  EXPECT_EQ(res.sheet.flag, Flag::amber) << "the light's low edge lies outside the rig's grid";
}

TEST(PreviewVolume, SparseAndDenseSeedingAndMent) {
  for (const double ppp : {0.02, 0.1}) {
    const ThesisRig r(thesis(ppp, sim::LightSheetProfile::uniform));
    SCOPED_TRACE(ppp);
    expect_sheet_at_truth(preview(r, r.grid()), r.rig.light_sheet(), 0.05);
  }
  const ThesisRig r(thesis(0.05, sim::LightSheetProfile::uniform));
  const PreviewResult ment = preview(r, r.grid(), {.algorithm = "ment"});
  expect_sheet_at_truth(ment, r.rig.light_sheet(), 0.03);
}

TEST(PreviewVolume, GaussianSheetCentre) {
  const ThesisRig r(thesis(0.05, sim::LightSheetProfile::gaussian));
  const PreviewResult res = preview(r, r.grid());
  ASSERT_TRUE(res.sheet.found);
  EXPECT_NEAR(res.sheet.position_mm, r.rig.light_sheet().centre_z_mm, 2 * res.grid.voxel_size)
      << "two slices: a peaked profile's centre scatters more than a flat one's edges";
  // Its width is of light^4, a Gaussian of half the sigma: narrower than 4 sigma of the light.
  EXPECT_LT(res.sheet.thickness_mm, 0.5 * r.rig.light_sheet().thickness_mm);
}

// Profiles of known shape: ghost level g outside, plateau 1 inside [lo, hi], linear edges.
std::vector<double> step_profile(int n, double lo, double hi, double g_low, double g_high, double ramp) {
  std::vector<double> p(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double z = k;
    const double rise = std::clamp((z - (lo - ramp / 2)) / ramp, 0.0, 1.0);
    const double fall = std::clamp(((hi + ramp / 2) - z) / ramp, 0.0, 1.0);
    const double g = z < (lo + hi) / 2 ? g_low : g_high;
    p[static_cast<std::size_t>(k)] = 2.0 * (g + (1 - g) * std::min(rise, fall));
  }
  return p;
}

TEST(SheetProfile, EdgesGhostLevelsAndSnrOfAKnownProfile) {
  const auto p = step_profile(100, 30.0, 60.0, 0.3, 0.4, 4.0);
  const SheetProfile s = analyse_depth_profile(p, -1.0, 0.1, {.cameras_at_low_z = true});
  ASSERT_TRUE(s.found);
  EXPECT_NEAR(s.low_edge_mm, -1.0 + 3.0, 0.02);
  EXPECT_NEAR(s.high_edge_mm, -1.0 + 6.0, 0.02);
  EXPECT_NEAR(s.position_mm, -1.0 + 4.5, 0.02);
  EXPECT_NEAR(s.thickness_mm, 3.0, 0.04);
  EXPECT_NEAR(s.ghost_front, 0.3, 1e-9) << "low z faces the cameras";
  EXPECT_NEAR(s.ghost_back, 0.4, 1e-9);
  EXPECT_GT(s.rsnr, 2.4);
  EXPECT_LT(s.rsnr, 3.0);
  EXPECT_EQ(s.flag, Flag::green) << "not judged without a grid";
  EXPECT_DOUBLE_EQ(s.intensity[45], 1.0);

  const SheetProfile flipped = analyse_depth_profile(p, -1.0, 0.1, {.cameras_at_low_z = false});
  EXPECT_NEAR(flipped.ghost_front, 0.4, 1e-9);

  const SheetProfile judged =
      analyse_depth_profile(p, -1.0, 0.1, {.grid_low_z_mm = 2.5, .grid_high_z_mm = 5.5});
  EXPECT_EQ(judged.flag, Flag::amber) << "the sheet reaches 0.5 mm beyond the grid on both sides";
}

TEST(SheetProfile, NoSheetOrOneRunningOffTheGrid) {
  const std::vector<double> flat(50, 3.0);
  EXPECT_FALSE(analyse_depth_profile(flat, 0, 1).found);
  const std::vector<double> zeros(50, 0.0);
  const SheetProfile dark = analyse_depth_profile(zeros, 0, 1);
  EXPECT_FALSE(dark.found);
  EXPECT_EQ(dark.flag, Flag::red);

  auto cut = step_profile(100, 30.0, 60.0, 0.3, 0.3, 2.0);
  cut.resize(50);  // the sheet runs off the grid's end
  const SheetProfile s = analyse_depth_profile(cut, 0, 1);
  EXPECT_FALSE(s.found);
  EXPECT_EQ(s.flag, Flag::red);
  EXPECT_NEAR(s.low_edge_mm, 30.0, 0.1) << "the edge that is there is still reported";
  EXPECT_TRUE(std::isnan(s.thickness_mm));

  auto unseen = step_profile(100, 30.0, 60.0, 0.3, 0.3, 2.0);
  for (int k = 61; k < 100; ++k) unseen[static_cast<std::size_t>(k)] = std::nan("");
  EXPECT_FALSE(analyse_depth_profile(unseen, 0, 1).found) << "slices nobody sees give no edge";
}

TEST(PreviewVolume, BadInputIsNamed) {
  const ThesisRig r(thesis(0.02, sim::LightSheetProfile::uniform));
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([&] { PreviewVolume(r.models, r.sizes, r.grid(), {.algorithm = "fmart"}); }).find("mlos or ment"),
            std::string::npos);
  EXPECT_NE(message([&] { PreviewVolume(r.models, r.sizes, r.grid(), {.binning = 0}); }).find("binning"),
            std::string::npos);
  EXPECT_NE(message([&] { PreviewVolume(r.models, r.sizes, r.grid(), {.depth_factor = 0.5}); }).find("depth_factor"),
            std::string::npos);
  VoxelGrid far = r.grid();
  far.origin.x += 100.0;
  EXPECT_NE(message([&] { PreviewVolume(r.models, r.sizes, far); }).find("seen by every camera"), std::string::npos);

  PreviewVolume pv(r.models, r.sizes, r.grid());
  PreviewResult out;
  std::vector<Image> images = r.exposure_a(0);
  images.pop_back();
  EXPECT_NE(message([&] { pv.reconstruct(images, out); }).find("3 images for 4 cameras"), std::string::npos);
  images.push_back(Image::allocate(100, 100, SampleType::u16));
  EXPECT_NE(message([&] { pv.reconstruct(images, out); }).find("camera 3 image is 100 x 100"), std::string::npos);
  images.back() = Image();
  EXPECT_NE(message([&] { pv.reconstruct(images, out); }).find("camera 3 has no image"), std::string::npos);
}

}  // namespace
}  // namespace tomorig::quicklook
