// The session -> reconstruction set-up: one default per parameter (the reconstruction
// library's), the rig file's [processing] keys when present, the command line above both.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_geometry.h"
#include "temp_dir.h"

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
  choices.psf_file = file;
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
  choices.psf_file = (dir.path() / "missing.toml").string();
  EXPECT_THROW(pipeline::reconstruction_setup(d, {}, choices), Error);
}

}  // namespace
}  // namespace tomorig::testing
