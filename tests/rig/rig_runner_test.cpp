// rig::RigRunner: the in-process rig (simulated trigger and cameras -> stream -> Recorder),
// options in and a report out, checked against the session it wrote.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "temp_dir.h"
#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/rig/rig_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

rig::RigRunOptions fast_options(const std::filesystem::path& out, std::uint64_t sets) {
  rig::RigRunOptions options;
  options.acquisition.sets = sets;
  options.acquisition.pacing = trigger::Pacing::as_fast_as_consumed;
  options.recorder.out = out;
  options.status_endpoint = "none";
  return options;
}

TEST(RigRunner, RecordsEveryTriggeredSetWithTheSimulatorsTruth) {
  TempDir tmp;
  const config::RigConfig rig = config::default_rig_config();
  rig::RigRunner runner(rig, fast_options(tmp / "run.h5", 3));
  EXPECT_EQ(runner.status_endpoint(), "");
  const rig::RigRunReport report = runner.run();

  EXPECT_EQ(report.recording.written, 3u);
  EXPECT_EQ(report.cameras, rig.cameras.size());
  EXPECT_EQ(report.frames_lost, 0u);
  EXPECT_TRUE(report.failure.empty()) << report.failure;
  EXPECT_FALSE(report.stopped);
  EXPECT_GT(report.file_bytes, 0u);
  EXPECT_NE(report.brief().find("3 sets x 4 cameras"), std::string::npos) << report.brief();

  const storage::SessionReader session(tmp / "run.h5");
  EXPECT_TRUE(session.recording_complete());
  EXPECT_EQ(session.set_count(), 3u);
  EXPECT_EQ(session.missing_frames(), 0);
  EXPECT_EQ(session.info().rig_config_toml, rig.source_text);
  ASSERT_TRUE(session.has_truth());
  EXPECT_EQ(session.truth_set_count(), 3u);
  EXPECT_FALSE(session.truth_set(2).particles_a.empty());
}

TEST(RigRunner, ItsStagesSeeTheRecordedSetsAndReport) {
  TempDir tmp;
  rig::RigRunOptions options = fast_options(tmp / "run.h5", 4);
  options.stages = {pipeline::parse_stage_spec("frame-stats:full_scale=65535,skip=false"),
                    pipeline::parse_stage_spec("recorder:out=" + (tmp / "copy.h5").string())};
  rig::RigRunner runner(config::default_rig_config(), options);
  const rig::RigRunReport report = runner.run();
  ASSERT_EQ(report.stages.size(), 2u);
  EXPECT_EQ(report.stages[0].name, "frame-stats");
  EXPECT_EQ(report.stages[0].processed, 4u);  // it does not skip: it sees every set
  EXPECT_EQ(report.stages[0].status["cameras"].size(), 4u);
  EXPECT_EQ(report.stages[1].processed, 4u);
  // The recorder stage's copy holds what the rig's own recorder wrote.
  const storage::SessionReader original(tmp / "run.h5"), copy(tmp / "copy.h5");
  EXPECT_EQ(copy.set_count(), original.set_count());
  EXPECT_EQ(copy.info().rig_config_toml, original.info().rig_config_toml);
  EXPECT_EQ(copy.set_record(3).trigger_index, original.set_record(3).trigger_index);
}

TEST(RigRunner, ABadStageSettingFailsBeforeAnyFileExists) {
  TempDir tmp;
  rig::RigRunOptions options = fast_options(tmp / "run.h5", 1);
  options.stages = {pipeline::parse_stage_spec("frame-stats:fullscale=255")};
  EXPECT_THROW(rig::RigRunner(config::default_rig_config(), options), Error);
  EXPECT_FALSE(std::filesystem::exists(tmp / "run.h5.partial"));
}

TEST(RigRunner, AnExistingOutputIsRefusedBeforeTheRigIsBuilt) {
  TempDir tmp;
  const auto out = tmp.write("run.h5", "keep me");
  try {
    rig::RigRunner runner(config::default_rig_config(), fast_options(out, 1));
    FAIL() << "an existing output was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
  }
  EXPECT_EQ(read_text_file(out), "keep me");
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

TEST(RigRunner, AStopRequestEndsTheRunWithACompleteSession) {
  TempDir tmp;
  rig::RigRunner runner(config::default_rig_config(), fast_options(tmp / "run.h5", 10000));
  // Asked between sets: stop once the first sets are in the file.
  const rig::RigRunReport report = runner.run([](const rig::RecorderReport& so_far) { return so_far.written >= 2; });
  EXPECT_TRUE(report.stopped);
  EXPECT_GE(report.recording.written, 2u);
  EXPECT_LT(report.recording.written, 10000u);
  const storage::SessionReader session(tmp / "run.h5");
  EXPECT_TRUE(session.recording_complete());
  EXPECT_EQ(session.set_count(), report.recording.written);
}

}  // namespace
}  // namespace tomorig::testing
