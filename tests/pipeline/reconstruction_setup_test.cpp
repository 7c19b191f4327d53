// The session -> reconstruction set-up: one default per parameter (the reconstruction
// library's), the rig file's [processing] keys when present, the command line above both.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_geometry.h"
#include "temp_dir.h"
#include "tomorig/pipeline/spray_psf.h"
#include "tomorig/processing/calibration/pinhole_camera.h"

namespace tomorig::testing {
namespace {

std::string rig_with_processing(const std::string& keys) {
  std::string toml = config::default_rig_toml();
  const std::string table = "[processing]\n";
  toml.insert(toml.find(table) + table.size(), keys);
  return toml;
}

recon::ReconstructionOptions setup_options(const std::string& toml, const pipeline::ReconstructionChoices& choices) {
  const pipeline::SessionDescription d = pipeline::describe_recording("test rig", {}, toml, std::nullopt);
  return pipeline::reconstruction_setup(d, {}, choices).options;
}

TEST(ReconstructionSetup, AbsentKeysTakeTheLibrarysDefaults) {
  const recon::ReconstructionOptions library;
  const pipeline::ReconstructionChoices choices;
  EXPECT_EQ(choices.options.relaxation, library.relaxation);
  EXPECT_EQ(choices.options.mlos_threshold, library.mlos_threshold);
  EXPECT_EQ(choices.sigma_px, recon::kDefaultPsfSigmaPx);
  // The embedded rig names neither algorithm nor iterations.
  const recon::ReconstructionOptions o = setup_options(config::default_rig_toml(), choices);
  EXPECT_EQ(o.algorithm, library.algorithm);
  EXPECT_EQ(o.max_iterations, library.max_iterations);
}

TEST(ReconstructionSetup, TheRigFileOverridesTheLibraryAndTheCommandLineOverridesBoth) {
  const std::string toml = rig_with_processing("algorithm = \"smart\"\niterations = 3\n");
  pipeline::ReconstructionChoices reconstruct;  // `reconstruct`: the rig's algorithm counts
  recon::ReconstructionOptions o = setup_options(toml, reconstruct);
  EXPECT_EQ(o.algorithm, "smart");
  EXPECT_EQ(o.max_iterations, 3);

  pipeline::ReconstructionChoices process{.algorithm_from_rig = false};  // `process`: FMART unless told
  o = setup_options(toml, process);
  EXPECT_EQ(o.algorithm, recon::ReconstructionOptions{}.algorithm);
  EXPECT_EQ(o.max_iterations, 3);

  reconstruct.algorithm = "mlos";
  reconstruct.iterations = 5;
  reconstruct.options.mlos_threshold = 0.2;
  o = setup_options(toml, reconstruct);
  EXPECT_EQ(o.algorithm, "mlos");
  EXPECT_EQ(o.max_iterations, 5);
  EXPECT_EQ(o.mlos_threshold, 0.2);
}

TEST(ReconstructionSetup, AnInvalidStoredRigFailsOnlyWhenItIsNeeded) {
  const pipeline::SessionDescription d =
      pipeline::describe_recording("odd", {}, "# recorded from a stream\n[grid]\nnx = -1\n", std::nullopt);
  EXPECT_FALSE(d.rig.has_value());
  EXPECT_FALSE(d.rig_error.empty());
  EXPECT_THROW(pipeline::grid_from_session(d), Error);  // the grid would come from it
  pipeline::ReconstructionChoices choices;
  choices.grid = "16,16,16,0.1";
  EXPECT_THROW(pipeline::reconstruction_setup(d, {}, choices), Error);  // its [processing] might matter
}

TEST(ReconstructionSetup, APsfFileGivesEachCameraItsMeasuredSigmaOverDepth) {
  // The file `tomorig optics psf --psf-out` writes (docs/spray.md); cameras matched by id.
  TempDir dir;
  const std::string file = (dir.path() / "psf.toml").string();
  std::ofstream(file) << "voxel_mm = 0.03\n"
                         "[[cameras]]\nid = \"cam2\"\nz_mm = [-1, 1]\nchi_um = [50, 60]\nchi_voxel_um = [55, 66]\n"
                         "sigma_px = [0.8, 1.2]\n"
                         "[[cameras]]\nid = \"cam1\"\nz_mm = [0]\nchi_um = [40]\nchi_voxel_um = [45]\nsigma_px = [0.6]\n";
  const pipeline::SessionDescription d = pipeline::describe_recording(
      "two cameras", {{"cam1", 64, 64}, {"cam2", 64, 64}}, config::default_rig_toml(), std::nullopt);
  pipeline::ReconstructionChoices choices;
  choices.psf = file;
  const recon::ReconstructionInput in = pipeline::reconstruction_setup(d, {}, choices).input;
  ASSERT_EQ(in.psf.size(), 2u);
  EXPECT_DOUBLE_EQ(in.psf[0].at(3.0).sigma_u_px, 0.6);
  EXPECT_DOUBLE_EQ(in.psf[1].at(-1.0).sigma_u_px, 0.8);
  EXPECT_DOUBLE_EQ(in.psf[1].at(0.0).sigma_v_px, 1.0);  // linear between the depths
  EXPECT_DOUBLE_EQ(in.psf[1].at(1.0).sigma_u_px, 1.2);

  // A camera the file does not name is refused, naming it and what the file has.
  const pipeline::SessionDescription three = pipeline::describe_recording(
      "three cameras", {{"cam1", 64, 64}, {"cam2", 64, 64}, {"cam3", 64, 64}}, config::default_rig_toml(), std::nullopt);
  try {
    pipeline::reconstruction_setup(three, {}, choices);
    FAIL() << "cam3 has no PSF";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'cam3'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cam2, cam1"), std::string::npos) << e.what();
  }
  choices.psf = (dir.path() / "missing.toml").string();
  EXPECT_THROW(pipeline::reconstruction_setup(d, {}, choices), Error);
}

// --psf: chi(z) in object um becomes each camera's weight sigma in its own pixels at that depth.
TEST(SprayPsf, ChiBecomesSigmaInPixelsOfEachCameraAtEachDepth) {
  // A pinhole of f = 100 mm at 211 mm: scale 100 / 211 at z = 0, a 6.5 um pixel sees 13.7 um.
  const auto cam = calibration::PinholeCamera::yawed(0.0, 100.0, 6.5, 211.0, 640, 540);
  optics::VisibilitySetup setup;
  optics::CameraOptics o;
  o.id = "cam1";
  o.chi = {{-4.5, 60.0}, {0.0, 40.0}, {4.5, 60.0}};
  setup.cameras.push_back(o);
  const std::vector<storage::SessionCamera> cameras{{"cam1", 640, 540, PixelFormat::Mono16, 6.5}};
  const VoxelGrid grid = VoxelGrid::centred(10, 10, 10, 0.1);
  const std::vector<recon::PsfModel> psf = pipeline::psf_from_optics_setup(setup, cameras, {&cam}, grid);
  ASSERT_EQ(psf.size(), 1u);
  ASSERT_EQ(psf[0].samples.size(), 3u);
  const double object_px_um = 6.5 * 211.0 / 100.0;
  EXPECT_NEAR(psf[0].samples[1].sigma_u_px, 20.0 / object_px_um, 1e-3);
  EXPECT_EQ(psf[0].samples[1].sigma_u_px, psf[0].samples[1].sigma_v_px);
  // The magnification changes with depth (the camera looks along z): the same chi is more
  // pixels on the near side than on the far side.
  EXPECT_NE(psf[0].samples[0].sigma_u_px, psf[0].samples[2].sigma_u_px);
  EXPECT_NEAR(psf[0].samples[0].sigma_u_px + psf[0].samples[2].sigma_u_px, 2 * 30.0 / object_px_um, 0.05);

  // A set-up without the session's camera, and a PSF wider than the reconstruction allows.
  const std::vector<storage::SessionCamera> other{{"cam9", 640, 540, PixelFormat::Mono16, 6.5}};
  EXPECT_THROW(pipeline::psf_from_optics_setup(setup, other, {&cam}, grid), Error);
  setup.cameras[0].chi = {{0.0, 400.0}};  // sigma 14.6 px
  EXPECT_THROW(pipeline::psf_from_optics_setup(setup, cameras, {&cam}, grid), Error);
  // --psf truth needs a session with a spray truth.
  EXPECT_THROW(pipeline::spray_optics_setup("truth", std::nullopt), Error);
}

}  // namespace
}  // namespace tomorig::testing
