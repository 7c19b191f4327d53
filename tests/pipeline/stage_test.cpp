// Stages, their table, registry and runner, tested as odin-data tests its plugins: a FrameSet
// built from an array, configure(), process(), no sockets. The runner's skipping is made
// deterministic with a stage that holds its first set until the test lets it go.
#include <gtest/gtest.h>

#include <cstdint>
#include <future>
#include <stdexcept>
#include <string>

#include "tomorig/core/error.h"
#include "tomorig/pipeline/stage_chain.h"
#include "tomorig/pipeline/stage_registry.h"

namespace tomorig::testing {
namespace {

using pipeline::Stage;
using pipeline::StageTable;

// One camera whose frames are `width` x 1 u16 pixels: `bright` of them at `high`, the rest at `low`.
FrameSet row_set(int width, int bright, std::uint16_t low, std::uint16_t high, std::uint64_t trigger = 0) {
  FrameSet set;
  set.trigger_index = trigger;
  CameraFrames c;
  c.camera_id = "cam0";
  for (Frame* f : {&c.a, &c.b}) {
    f->image = Image::allocate(width, 1, SampleType::u16);
    for (int x = 0; x < width; ++x) f->image.row<std::uint16_t>(0)[x] = x < bright ? high : low;
  }
  set.cameras.push_back(std::move(c));
  return set;
}

TEST(StageTable, KeyValueTextKeepsCommasOfAValueAndTypesNumbers) {
  const StageTable t = StageTable::parse("window=32,32,16,overlap=0.5,iterations=6,skip=true,out=a.h5", "backend");
  EXPECT_EQ(t.text("window", ""), "32,32,16");
  EXPECT_DOUBLE_EQ(t.number("overlap", 0.75), 0.5);
  EXPECT_EQ(t.integer("iterations", 8), 6);
  EXPECT_TRUE(t.flag("skip", false));
  EXPECT_EQ(t.text("out", ""), "a.h5");
  EXPECT_DOUBLE_EQ(t.number("relaxation", 1.25), 1.25);  // absent: the caller's default
  EXPECT_NO_THROW(t.check_all_used());
}

TEST(StageTable, ErrorsNameTheStageAndTheKey) {
  const StageTable t = StageTable::parse("overlap=half,iteratons=6", "backend");
  try {
    t.number("overlap", 0.75);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("backend"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("overlap"), std::string::npos) << e.what();
  }
  t.integer("iterations", 8);
  try {
    t.check_all_used();  // the typo is caught, and the known keys listed
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'iteratons'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("iterations"), std::string::npos) << e.what();
  }
  EXPECT_THROW(StageTable::parse("=3", "x"), Error);
  EXPECT_THROW(StageTable::parse("novalue", "x"), Error);
}

TEST(StageRegistry, CreatesConfiguredStagesAndRefusesUnknownOnes) {
  pipeline::StageRegistry registry;
  pipeline::add_pipeline_stages(registry);
  EXPECT_THROW(registry.add("frame-stats", "again", nullptr), std::logic_error);
  const auto stage = registry.create(pipeline::parse_stage_spec("frame-stats:full_scale=255"));
  ASSERT_NE(stage, nullptr);
  EXPECT_TRUE(stage->may_skip());
  try {
    registry.create(pipeline::parse_stage_spec("quick-lok"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frame-stats"), std::string::npos) << e.what();  // the known ones
  }
  EXPECT_THROW(registry.create(pipeline::parse_stage_spec("frame-stats:full_scale=-1")), Error);
  EXPECT_THROW(registry.create(pipeline::parse_stage_spec("frame-stats:colour=red")), Error);
  EXPECT_THROW(registry.create(pipeline::parse_stage_spec("backend")), Error);  // no out=
}

TEST(FrameStatsStage, MeasuresMeanAndSaturationOfTheNewestSet) {
  pipeline::StageRegistry registry;
  pipeline::add_pipeline_stages(registry);
  const auto stage = registry.create(pipeline::parse_stage_spec("frame-stats:full_scale=1000"));
  stage->process(row_set(10, 2, 100, 2000, 1));  // older set: replaced by the next
  stage->process(row_set(10, 3, 100, 1000, 2));  // 3 of 10 pixels saturated, mean (7*100 + 3*1000)/10
  const nlohmann::json s = stage->status();
  EXPECT_EQ(s["trigger_index"], 2);
  ASSERT_EQ(s["cameras"].size(), 1u);
  EXPECT_DOUBLE_EQ(s["cameras"][0]["mean"][0].get<double>(), 370.0);
  EXPECT_DOUBLE_EQ(s["cameras"][0]["saturated_fraction"][1].get<double>(), 0.3);
}

// Holds its first set until released, so the test knows the stage is busy while it offers more.
class HeldStage final : public Stage {
 public:
  std::promise<void> entered, release;
  std::vector<std::uint64_t> seen;
  bool ended = false;
  bool skip = true;
  std::size_t waiting = 1;
  void configure(const StageTable&) override {}
  void process(const FrameSet& set) override {
    if (seen.empty()) {
      entered.set_value();
      release.get_future().wait();
    }
    seen.push_back(set.trigger_index);
    if (set.trigger_index == 99) throw bad_input("set 99 is cursed");
  }
  void end() override { ended = true; }
  bool may_skip() const override { return skip; }
  std::size_t max_waiting_sets() const override { return waiting; }
};

// Offers set 1, waits until the stage is held inside it, offers sets 2 to `last` meanwhile,
// then releases the stage and ends the runner (which processes what still waits).
struct HeldRun {
  pipeline::StageReport report;
  std::vector<std::uint64_t> seen;
  bool ended = false;
};
HeldRun offer_while_held(std::uint64_t last, std::size_t waiting) {
  auto owned = std::make_unique<HeldStage>();
  owned->waiting = waiting;
  HeldStage& stage = *owned;
  std::future<void> entered = stage.entered.get_future();
  pipeline::StageRunner runner("held", std::move(owned));
  runner.begin({});
  runner.offer(row_set(4, 0, 1, 1, 1));
  entered.wait();  // set 1 is being processed
  for (std::uint64_t t = 2; t <= last; ++t) runner.offer(row_set(4, 0, 1, 1, t));
  stage.release.set_value();
  HeldRun run;
  run.report = runner.end();
  run.seen = stage.seen;
  run.ended = stage.ended;
  return run;
}

TEST(StageRunner, ASkippingStageTakesTheNewestSetAndCountsTheOthers) {
  const HeldRun run = offer_while_held(5, 1);
  EXPECT_EQ(run.seen, (std::vector<std::uint64_t>{1, 5}));  // 2, 3, 4 were overtaken
  EXPECT_EQ(run.report.offered, 5u);
  EXPECT_EQ(run.report.processed, 2u);
  EXPECT_EQ(run.report.skipped, 3u);
  EXPECT_TRUE(run.ended);
  EXPECT_NE(run.report.brief().find("3 skipped"), std::string::npos) << run.report.brief();
}

TEST(StageRunner, AStageThatMayLagKeepsItsNewestSetsWaitingAndSkipsOnlyTheOldest) {
  const HeldRun run = offer_while_held(6, 3);
  EXPECT_EQ(run.seen, (std::vector<std::uint64_t>{1, 4, 5, 6}));  // 2 and 3 gave way, in order
  EXPECT_EQ(run.report.offered, 6u);
  EXPECT_EQ(run.report.processed, 4u);
  EXPECT_EQ(run.report.skipped, 2u);
}

TEST(StageRunner, ALosslessStageSeesEverySetAndItsErrorsReachTheCaller) {
  auto owned = std::make_unique<HeldStage>();
  owned->skip = false;
  owned->release.set_value();  // never held: it runs in the caller's thread
  HeldStage& stage = *owned;
  pipeline::StageChain chain;
  chain.add("held", std::move(owned));
  chain.begin({});
  for (std::uint64_t t = 1; t <= 4; ++t) chain.push(row_set(4, 0, 1, 1, t));
  EXPECT_THROW(chain.push(row_set(4, 0, 1, 1, 99)), Error);
  const std::vector<pipeline::StageReport> reports = chain.end();
  EXPECT_EQ(stage.seen, (std::vector<std::uint64_t>{1, 2, 3, 4, 99}));
  EXPECT_EQ(reports.at(0).processed, 4u);
  EXPECT_EQ(reports.at(0).skipped, 0u);
}

TEST(StageRunner, AFailingSkippingStageStopsAloneAndReportsWhy) {
  auto owned = std::make_unique<HeldStage>();
  owned->release.set_value();
  HeldStage& stage = *owned;
  std::future<void> entered = stage.entered.get_future();
  pipeline::StageRunner runner("held", std::move(owned));
  runner.begin({});
  runner.offer(row_set(4, 0, 1, 1, 99));  // its first set throws
  entered.wait();
  const pipeline::StageReport report = runner.end();
  EXPECT_EQ(report.processed, 0u);
  EXPECT_NE(report.error.find("cursed"), std::string::npos) << report.error;
  EXPECT_FALSE(stage.ended);  // end() is not called on a stage that failed
}

}  // namespace
}  // namespace tomorig::testing
