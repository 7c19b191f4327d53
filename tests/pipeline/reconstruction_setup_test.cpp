// The session -> reconstruction set-up: one default per parameter (the reconstruction
// library's), the rig file's [processing] keys when present, the command line above both.
#include <gtest/gtest.h>

#include <string>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/session_geometry.h"

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

}  // namespace
}  // namespace tomorig::testing
