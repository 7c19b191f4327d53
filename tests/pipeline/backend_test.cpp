// pipeline::run_backend on a small simulated session (tpiv-thesis, reconstructed on a sub-grid
// at the centre): overlapped and sequential runs agree, an interrupted run resumes without
// redoing a set, and the back-end as a stage on a replayed session writes the same kind of
// results file. Accuracy against the analytic flow is checked end to end in
// tests/apps/process_cli_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

#include "temp_dir.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/backend.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/rig/simulate_session.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/results_file.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {
namespace fs = std::filesystem;

class Backend : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    config::RigConfig rig = config::default_rig_config();
    rig.simulation->sets = 2;
    rig.simulation->ppp = 0.05;
    rig::run_simulation_to_session(rig, session(), storage::Compression::none, false);
  }
  static void TearDownTestSuite() { dir_.reset(); }
  static fs::path session() { return *dir_ / "s.h5"; }

  static pipeline::BackendOptions options(const fs::path& out) {
    pipeline::BackendOptions o;
    o.out = out;
    o.calib = "truth";
    o.reconstruction.grid = "64,64,160,0.0195";
    o.correlation.window = "32,32,32";
    o.correlation.overlap = 0.5;
    o.correlation.deformation_passes = 1;
    return o;
  }
  static std::unique_ptr<TempDir> dir_;
};
std::unique_ptr<TempDir> Backend::dir_;

TEST_F(Backend, OverlappedAndSequentialRunsWriteTheSameField) {
  pipeline::BackendOptions sequential = options(*dir_ / "sequential.h5");
  sequential.sequential = true;
  const pipeline::BackendReport a = pipeline::run_backend(session(), sequential);
  EXPECT_FALSE(a.overlapped);
  EXPECT_EQ(a.sets_in_file, 2u);
  EXPECT_EQ(a.sets_processed, 2u);
  EXPECT_GT(a.mean_valid_fraction, 0.3);  // a sanity check: accuracy against the flow is process_cli_test's
  // Where the time went: every stage of every set counted once, so one set at a time the stages
  // add up to no more than the run; the run used CPU and the JSON carries it all.
  const pipeline::BackendStageSeconds& t = a.stage_seconds;
  EXPECT_GT(t.load, 0.0);
  EXPECT_GT(t.reconstruction, 0.0);
  EXPECT_GT(t.correlation, 0.0);
  EXPECT_GT(t.write, 0.0);
  EXPECT_GE(t.preprocess, 0.0);
  EXPECT_LT(t.preprocess, 0.01) << "no chain: nothing to preprocess";
  EXPECT_LE(t.load + t.preprocess + t.reconstruction + t.correlation + t.write, a.seconds);
  EXPECT_GT(a.cpu_user_seconds, 0.0);
  EXPECT_GE(a.minor_page_faults, 0);
  const nlohmann::json json = a.to_json();
  EXPECT_DOUBLE_EQ(json.at("stage_seconds").at("correlation").get<double>(), t.correlation);
  EXPECT_DOUBLE_EQ(json.at("cpu_seconds").get<double>(), a.cpu_user_seconds + a.cpu_system_seconds);
  EXPECT_TRUE(json.contains("minor_page_faults"));

  pipeline::BackendOptions overlapped = options(*dir_ / "overlapped.h5");
  overlapped.png = *dir_ / "mean-slice.png";  // the mean field's middle z-slice, axes in mm
  const pipeline::BackendReport b = pipeline::run_backend(session(), overlapped);
  EXPECT_EQ(b.sets_in_file, 2u);
  const Image slice = storage::read_image(overlapped.png);
  EXPECT_GT(slice.width(), 200);
  EXPECT_GT(slice.height(), 200);
  const storage::ResultsReader ra(a.out), rb(b.out);
  for (std::uint64_t s = 0; s < 2; ++s) {
    const VectorField fa = ra.read_set(s).field, fb = rb.read_set(s).field;
    ASSERT_EQ(fa.displacement.size(), fb.displacement.size());
    for (std::size_t i = 0; i < fa.displacement.size(); ++i) {
      EXPECT_NEAR(fa.displacement[i].x, fb.displacement[i].x, 1e-3);
      EXPECT_NEAR(fa.displacement[i].z, fb.displacement[i].z, 1e-3);
    }
  }
}

TEST_F(Backend, AnInterruptedRunResumesWithoutRedoingASet) {
  const fs::path out = *dir_ / "resumed.h5";
  pipeline::BackendHooks stop_after_one;
  std::uint64_t done = 0;
  stop_after_one.set_done = [&](const pipeline::BackendSetDone&) { ++done; };
  stop_after_one.should_stop = [&] { return done >= 1; };
  const pipeline::BackendReport first = pipeline::run_backend(session(), options(out), stop_after_one);
  EXPECT_TRUE(first.interrupted);
  EXPECT_EQ(first.sets_in_file, 1u);
  EXPECT_EQ(storage::ResultsReader(out).set_indices().size(), 1u);  // valid as it stands

  std::vector<std::uint64_t> redone;
  pipeline::BackendHooks watch;
  watch.set_done = [&](const pipeline::BackendSetDone& s) { redone.push_back(s.index); };
  const pipeline::BackendReport second = pipeline::run_backend(session(), options(out), watch);
  EXPECT_FALSE(second.interrupted);
  EXPECT_EQ(second.sets_resumed, 1u);
  EXPECT_EQ(second.sets_processed, 1u);
  EXPECT_EQ(redone, (std::vector<std::uint64_t>{1}));
  EXPECT_EQ(second.sets_in_file, 2u);
  EXPECT_EQ(second.nodes[0] * second.nodes[1] * second.nodes[2] > 0, true);
}

TEST_F(Backend, BadOptionsAreRefusedBeforeAnyWork) {
  pipeline::BackendOptions o = options(*dir_ / "never.h5");
  o.correlation.window = "128,128,128";  // larger than the 64-voxel grid
  EXPECT_THROW(pipeline::run_backend(session(), o), Error);
  o = options(*dir_ / "never.h5");
  o.smooth = {1.0, 1.0};
  EXPECT_THROW(pipeline::run_backend(session(), o), Error);
  EXPECT_FALSE(fs::exists(*dir_ / "never.h5"));
}

TEST_F(Backend, TheBackendStageProcessesAReplayedSession) {
  pipeline::StageRegistry registry;
  pipeline::add_pipeline_stages(registry);
  const fs::path out = *dir_ / "stage.h5";
  pipeline::StageChain chain = pipeline::make_chain(
      registry, {pipeline::parse_stage_spec("backend:out=" + out.string() +
                                            ",calib=truth,grid=64,64,160,0.0195,window=32,32,32,overlap=0.5,"
                                            "deformation_passes=1")});
  const storage::SessionReader reader(session());
  chain.begin(pipeline::describe_session(reader));
  for (std::uint64_t s = 0; s < reader.set_count(); ++s) chain.push(reader.read_set(s));
  const std::vector<pipeline::StageReport> reports = chain.end();
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0].processed, 2u);
  EXPECT_EQ(reports[0].skipped, 0u);
  EXPECT_GT(reports[0].status["mean_valid_fraction"].get<double>(), 0.3);
  EXPECT_EQ(storage::ResultsReader(out).set_indices().size(), 2u);
}

}  // namespace
}  // namespace tomorig::testing
