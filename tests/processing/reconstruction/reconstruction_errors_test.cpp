// Bad input to the reconstructors: each case is refused with tomorig::Error (bad_input) and a
// message that says what is wrong, never a crash or an OOM kill.
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "reduced_case.h"
#include "tomorig/core/error.h"

namespace {

using namespace tomorig;

const recon_test::ReducedCase& tiny_case() {
  static const recon_test::ReducedCase rc = recon_test::make_case(24, 12, 40, 0.003);
  return rc;
}

// Runs every algorithm on `input` and checks that each refuses it with a message containing `needle`.
void expect_refused(const recon::ReconstructionInput& input, const std::string& needle,
                    recon::ReconstructionOptions options = {}) {
  for (const char* algorithm : {"mlos", "mart", "smart", "fmart"}) {
    options.algorithm = algorithm;
    recon::ReconstructionReport report;
    try {
      recon::make_reconstructor(options)->reconstruct(input, report);
      ADD_FAILURE() << algorithm << " accepted the input; expected an error containing '" << needle << "'";
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input) << algorithm;
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << algorithm << ": " << e.what();
    }
  }
}

TEST(ReconstructionErrors, CameraCountDiffersFromImageCount) {
  recon::ReconstructionInput in = tiny_case().input();
  in.images.pop_back();
  expect_refused(in, "4 camera models (calibration) but 3 images");
}

TEST(ReconstructionErrors, ImageSizeDiffersFromCalibration) {
  recon::ReconstructionInput in = tiny_case().input();
  in.sensor_sizes.assign(4, {40, 40});
  in.sensor_sizes[2] = {512, 512};
  expect_refused(in, "camera 2 image is 40 x 40 px but its calibration is for 512 x 512");
}

TEST(ReconstructionErrors, GridNoCameraSees) {
  recon::ReconstructionInput in = tiny_case().input();
  in.grid.origin = {50.0, 0.0, 0.0};  // 50 mm to the side: far outside every 40 px view
  expect_refused(in, "sees none of the grid");
}

TEST(ReconstructionErrors, VolumeTooLargeForTheMemoryLimit) {
  recon::ReconstructionOptions o;
  o.memory_limit_mb = 0.01;
  expect_refused(tiny_case().input(), "MB are allowed (memory_limit_mb)", o);
}

TEST(ReconstructionErrors, VolumeTooLargeForTheMemoryAvailable) {
  // A background in every pixel and no threshold: every voxel of a 1600^3 grid could be active,
  // which no machine here can hold. The refusal comes before any allocation of that size.
  recon::ReconstructionInput in = tiny_case().input();
  for (Image& image : in.images) {
    image = image.clone();
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x) image.at<float>(x, y) += 1.0f;
  }
  in.grid = VoxelGrid::centred(1600, 1600, 1600, 0.0195 * 24 / 1600);
  recon::ReconstructionOptions o;
  o.mlos_threshold = 0.0;
  expect_refused(in, "MB are available (80 % of MemAvailable)", o);
}

TEST(ReconstructionErrors, GridBeyond32BitIndices) {
  recon::ReconstructionInput in = tiny_case().input();
  in.grid = VoxelGrid::centred(4096, 4096, 512, 0.001);
  expect_refused(in, "32-bit indices");
}

TEST(ReconstructionErrors, AllZeroImage) {
  recon::ReconstructionInput in = tiny_case().input();
  in.images[1] = Image::allocate(40, 40, SampleType::u16);
  expect_refused(in, "camera 1 image is all zero");
}

TEST(ReconstructionErrors, NaNPixel) {
  recon::ReconstructionInput in = tiny_case().input();
  in.images[3] = in.images[3].clone();
  in.images[3].at<float>(7, 5) = std::numeric_limits<float>::quiet_NaN();
  expect_refused(in, "camera 3 image has a non-finite pixel (nan) at x = 7, y = 5");
}

TEST(ReconstructionErrors, BadPsf) {
  recon::ReconstructionInput in = tiny_case().input();
  in.psf.assign(4, recon::PsfModel::constant(0.5));
  in.psf[0].samples.push_back({-1.0, 0.5, 0.5});  // not ascending
  expect_refused(in, "camera 0 PSF");
  in.psf.pop_back();
  expect_refused(in, "3 PSF models for 4 cameras");
}

TEST(ReconstructionErrors, BadOptionsAndAlgorithms) {
  recon::ReconstructionOptions o;
  o.relaxation = 3;
  EXPECT_THROW(recon::make_reconstructor(o), Error);
  o = {};
  o.lut_steps = 10;
  EXPECT_THROW(recon::make_reconstructor(o), Error);
  o = {};
  o.mlos_threshold = std::nan("");
  EXPECT_THROW(recon::make_reconstructor(o), Error);
  o = {};
  o.algorithm = "ment";
  EXPECT_NO_THROW(recon::make_reconstructor(o));
  o.algorithm = "art";
  EXPECT_THROW(recon::make_reconstructor(o), Error);
  EXPECT_NO_THROW(recon::ReconstructionOptions{}.validate());  // the defaults are valid
}

}  // namespace
