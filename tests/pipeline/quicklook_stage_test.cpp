// The quicklook stage through the registry, fed simulated sets as a live rig feeds them: it
// measures every set it gets, makes preview volumes on its own thread, hands its numbers to the
// recording's store (statistics per set, the sheet and drift per preview) and judges them against
// the simulator's truth; without camera models it still measures, and says why there is no preview.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <mutex>
#include <vector>

#include "tomorig/config/rig_config.h"
#include "tomorig/core/error.h"
#include "tomorig/pipeline/quicklook_settings.h"
#include "tomorig/pipeline/session_geometry.h"
#include "tomorig/pipeline/stage_chain.h"
#include "tomorig/pipeline/stage_registry.h"
#include "tomorig/rig/rig_stages.h"
#include "tomorig/rig/simulate_session.h"
#include "tomorig/simulators/simulated_rig.h"

namespace tomorig::testing {
namespace {

using pipeline::StageSpec;

struct Stored {
  std::mutex mutex;
  std::vector<storage::QuickLookRecord> records;
};

struct DefaultRig {
  config::RigConfig rig = config::default_rig_config();
  sim::SimulatedRig simulated{rig::simulation_options_from(rig)};
  std::vector<storage::SessionCamera> cameras;
  storage::SessionTruth truth;

  DefaultRig() {
    for (const sim::SimulatedCamera& c : simulated.cameras()) {
      cameras.push_back({c.spec.id, c.spec.width, c.spec.height, PixelFormat::Mono16, c.spec.pixel_pitch_um});
      truth.cameras.push_back(rig::truth_camera_of(c));
    }
  }
  pipeline::SessionDescription recording(bool with_truth, Stored* stored) const {
    pipeline::SessionDescription d = pipeline::describe_recording(
        "test rig", cameras, rig.source_text, with_truth ? std::optional(truth) : std::nullopt);
    if (stored != nullptr)
      d.store_quicklook = [stored](const storage::QuickLookRecord& r) {
        std::lock_guard lock(stored->mutex);
        stored->records.push_back(r);
      };
    return d;
  }
};

TEST(QuickLookStage, MeasuresEverySetItGetsAndStoresTheSheetOfItsPreviews) {
  const DefaultRig rig;
  Stored stored;
  pipeline::StageChain chain = pipeline::make_chain(rig::all_stages(), {pipeline::parse_stage_spec("quicklook")});
  chain.begin(rig.recording(true, &stored));
  constexpr std::uint64_t kSets = 3;
  for (std::uint64_t k = 0; k < kSets; ++k) {
    FrameSet set = rig.simulated.render_set(k).frames;
    set.set_index = k;
    chain.push(set);
  }
  const std::vector<pipeline::StageReport> reports = chain.end();
  ASSERT_EQ(reports.size(), 1u);
  const pipeline::StageReport& r = reports[0];
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.processed + r.skipped, kSets);
  EXPECT_EQ(r.status.at("analysed").get<std::uint64_t>(), r.processed);
  EXPECT_GE(r.status.at("previews").get<std::uint64_t>(), 1u) << "the newest set is always reconstructed at the end";
  EXPECT_EQ(r.status.at("preview"), "mlos");
  EXPECT_TRUE(r.status.at("publish").is_null());

  // Statistics rows, one per set the stage measured, near the truth (ppp 0.05).
  std::size_t statistics = 0, previews = 0;
  for (const storage::QuickLookRecord& record : stored.records) {
    ASSERT_EQ(record.cameras.size(), 4u);
    if (record.preview) {
      ++previews;
      EXPECT_NEAR(record.sheet_position_mm, rig.simulated.light_sheet().centre_z_mm, 2 * 0.0195);
      EXPECT_NEAR(record.sheet_thickness_mm, rig.simulated.light_sheet().thickness_mm,
                  0.03 * rig.simulated.light_sheet().thickness_mm);
      EXPECT_TRUE(std::isfinite(record.rsnr));
    } else {
      ++statistics;
      for (const auto& c : record.cameras) EXPECT_NEAR(c.ppp[0], 0.05, 0.005);
    }
  }
  EXPECT_EQ(statistics, r.processed);
  EXPECT_EQ(previews, r.status.at("previews").get<std::size_t>());
}

// The quick-look yields the CPU to the recorder: its statistics thread at nice 5, its preview
// thread at nice 10 (the defaults), the thread that pushes the sets (the recorder's) untouched.
// The store callback runs on the thread that produced the row, so it reads that thread's nice.
TEST(QuickLookStage, ItsThreadsYieldToTheRecorder) {
  const DefaultRig rig;
  struct Seen {
    std::mutex mutex;
    std::vector<std::pair<bool, int>> rows;  // preview row?, the storing thread's nice
  } seen;
  pipeline::SessionDescription recording = rig.recording(true, nullptr);
  recording.store_quicklook = [&seen](const storage::QuickLookRecord& r) {
    const int nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
    std::lock_guard lock(seen.mutex);
    seen.rows.emplace_back(r.preview, nice);
  };
  const int pusher_nice = getpriority(PRIO_PROCESS, static_cast<id_t>(gettid()));
  pipeline::StageChain chain = pipeline::make_chain(rig::all_stages(), {pipeline::parse_stage_spec("quicklook")});
  chain.begin(recording);
  chain.push(rig.simulated.render_set(0).frames);
  const pipeline::StageReport r = chain.end().at(0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.status.at("nice").at("statistics"), 5);
  EXPECT_EQ(r.status.at("nice").at("preview"), 10);
  EXPECT_FALSE(r.status.contains("nice_error")) << r.status.dump();
  EXPECT_FALSE(r.status.contains("preview_nice_error")) << r.status.dump();
  bool statistics = false, preview = false;
  for (const auto& [is_preview, nice] : seen.rows) {
    EXPECT_EQ(nice, std::max(pusher_nice, is_preview ? 10 : 5)) << (is_preview ? "preview" : "statistics");
    (is_preview ? preview : statistics) = true;
  }
  EXPECT_TRUE(statistics && preview);
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())), pusher_nice) << "the pushing thread is untouched";
}

TEST(QuickLookStage, WithoutCameraModelsItMeasuresAndSaysWhyThereIsNoPreview) {
  const DefaultRig rig;
  pipeline::StageChain chain =
      pipeline::make_chain(rig::all_stages(), {pipeline::parse_stage_spec("quicklook:store=false")});
  chain.begin(rig.recording(false, nullptr));  // no truth, no calibration file in the rig
  chain.push(rig.simulated.render_set(0).frames);
  const pipeline::StageReport r = chain.end().at(0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.status.at("analysed"), 1);
  EXPECT_EQ(r.status.at("previews"), 0);
  EXPECT_NE(r.status.at("preview").get<std::string>().find("off: "), std::string::npos) << r.status.dump();
  EXPECT_NE(r.status.at("preview").get<std::string>().find("calibration"), std::string::npos) << r.status.dump();
}

TEST(QuickLookSettings, RigKeysOverrideTheLibraryDefaultsAndOnlyThose) {
  const pipeline::QuickLookSettings defaults = pipeline::quicklook_settings(nullptr);
  const quicklook::QuickLookOptions library;
  EXPECT_EQ(defaults.statistics.targets.ppp.low, library.targets.ppp.low);
  EXPECT_EQ(defaults.preview.algorithm, quicklook::PreviewVolumeOptions{}.algorithm);

  const config::RigConfig rig = config::parse_rig_config(config::default_rig_toml() + R"(
[quicklook]
ppp = [0.03, 0.06]
detail_tiles = 64
saturated_fraction_max = 0.002
[quicklook.dt_check]
windows = [3, 2]
displacement_px = [2.0, 9.0]
[quicklook.drift]
warn_px = 0.2
subvolumes = [4, 3, 2]
[quicklook.preview]
algorithm = "ment"
binning = 4
)");
  const pipeline::QuickLookSettings s = pipeline::quicklook_settings(&rig);
  EXPECT_EQ(s.statistics.targets.ppp.low, 0.03);
  EXPECT_EQ(s.statistics.targets.ppp.high, 0.06);
  EXPECT_EQ(s.statistics.targets.ppp.amber, library.targets.ppp.amber) << "amber bands stay the library's";
  EXPECT_EQ(s.statistics.targets.saturated_fraction.high, 0.002);
  EXPECT_EQ(s.statistics.targets.diameter_px.high, library.targets.diameter_px.high) << "absent: the library's";
  EXPECT_EQ(s.statistics.tile_px, library.tile_px);
  EXPECT_EQ(s.statistics.detail_tiles, 64);
  EXPECT_EQ(defaults.statistics.detail_tiles, library.detail_tiles);
  EXPECT_EQ(s.dt_check.windows_x, 3);
  EXPECT_EQ(s.dt_check.windows_y, 2);
  EXPECT_EQ(s.dt_check.displacement_px.high, 9.0);
  EXPECT_EQ(s.dt_check.window_px, quicklook::DtCheckOptions{}.window_px);
  EXPECT_EQ(s.drift.warn_px, 0.2);
  EXPECT_EQ(s.drift.subvolumes_z, 2);
  EXPECT_EQ(s.drift.window_sets, quicklook::DriftOptions{}.window_sets);
  EXPECT_EQ(s.preview.algorithm, "ment");
  EXPECT_EQ(s.preview.binning, 4);
  EXPECT_EQ(s.preview.depth_factor, quicklook::PreviewVolumeOptions{}.depth_factor);
}

TEST(QuickLookSettings, SprayKeysSetTheShadowLooksTargets) {
  const pipeline::QuickLookSettings defaults = pipeline::quicklook_settings(nullptr);
  const quicklook::ShadowLookOptions library;
  EXPECT_EQ(defaults.shadow.targets.energy_ratio.low, library.targets.energy_ratio.low);
  EXPECT_EQ(defaults.shadow.binning, library.binning);
  EXPECT_FALSE(defaults.shadow.targets.shadow_count) << "not judged unless the rig sets it";

  const config::RigConfig rig = config::parse_rig_config(config::default_rig_toml() + R"(
[quicklook.spray]
coverage_max = 0.08
energy_tolerance = 0.15
shadow_count = [200, 1500]
min_intensity_max = 0.4
binning = 2
)");
  const pipeline::QuickLookSettings s = pipeline::quicklook_settings(&rig);
  const quicklook::ShadowTargets& t = s.shadow.targets;
  EXPECT_EQ(t.shadow_coverage.high, 0.08);
  EXPECT_EQ(t.shadow_coverage.amber, library.targets.shadow_coverage.amber) << "amber bands stay the library's";
  EXPECT_DOUBLE_EQ(t.energy_ratio.low, 0.85);
  EXPECT_DOUBLE_EQ(t.energy_ratio.high, 1.15);
  ASSERT_TRUE(t.shadow_count);
  EXPECT_EQ(t.shadow_count->low, 200);
  EXPECT_EQ(t.shadow_count->amber, quicklook::ShadowTargets::shadow_count_amber);
  ASSERT_TRUE(t.min_intensity);
  EXPECT_EQ(t.min_intensity->high, 0.4);
  EXPECT_EQ(t.uniformity.low, library.targets.uniformity.low) << "absent: the library's";
  EXPECT_EQ(t.bright_fraction.high, library.targets.bright_fraction.high);
  EXPECT_EQ(s.shadow.binning, 2);
  EXPECT_EQ(s.shadow.reference_sets, library.reference_sets);
}

TEST(QuickLookStage, FramesTooSmallForTheDtCheckStillGetTheirStatistics) {
  // 40 x 30 frames: statistics yes, no 64 px correlation window fits.
  std::vector<storage::SessionCamera> cameras = {{"tiny", 40, 30, PixelFormat::Mono16, 7.4}};
  FrameSet set;
  CameraFrames c;
  c.camera_id = "tiny";
  for (Frame* f : {&c.a, &c.b}) {
    f->image = Image::allocate(40, 30, SampleType::u16);
    for (int y = 0; y < 30; ++y)
      for (int x = 0; x < 40; ++x) f->image.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(100 + (x * 7 + y * 3) % 11);
  }
  set.cameras.push_back(std::move(c));
  Stored stored;
  pipeline::StageChain chain = pipeline::make_chain(rig::all_stages(), {pipeline::parse_stage_spec("quicklook")});
  pipeline::SessionDescription recording = pipeline::describe_recording("tiny rig", cameras, "", std::nullopt);
  recording.store_quicklook = [&stored](const storage::QuickLookRecord& r) { stored.records.push_back(r); };
  chain.begin(recording);
  chain.push(set);
  const pipeline::StageReport r = chain.end().at(0);
  EXPECT_TRUE(r.error.empty()) << r.error;
  EXPECT_EQ(r.status.at("analysed"), 1);
  ASSERT_EQ(stored.records.size(), 1u);
  EXPECT_TRUE(std::isfinite(stored.records[0].cameras[0].background[0])) << "the statistics were measured";
  EXPECT_TRUE(std::isnan(stored.records[0].cameras[0].dt_displacement_px)) << "the Δt check was not";
}

TEST(QuickLookStage, BadSettingsAreNamedBeforeAnySet) {
  auto message = [](const std::string& spec) {
    try {
      pipeline::make_chain(rig::all_stages(), {pipeline::parse_stage_spec(spec)});
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::bad_input);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("quicklook:preview=fmart").find("preview = fmart"), std::string::npos);
  EXPECT_NE(message("quicklook:thumbnail_px=2").find("thumbnail_px"), std::string::npos);
  EXPECT_NE(message("quicklook:nice=25").find("nice = 25"), std::string::npos);
  EXPECT_NE(message("quicklook:preview_nice=-1").find("preview_nice = -1"), std::string::npos);
  EXPECT_NE(message("quicklook:publsh=tcp://127.0.0.1:5999").find("publsh"), std::string::npos);
  EXPECT_NE(message("quicklook:publish=tcp://0.0.0.0:5999").find("allow_remote"), std::string::npos);
}

}  // namespace
}  // namespace tomorig::testing
