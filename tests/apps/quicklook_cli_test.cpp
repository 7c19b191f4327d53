// `tomorig inspect --png`: quick-look PNGs of one set that open in any image viewer.
// `tomorig bench quicklook`: the recorder plus the quick-look at the rig's rate, and its figures.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::testing {
namespace {

TEST(QuicklookCli, InspectWritesOnePngPerFrameOfTheSet) {
  TempDir dir;
  const std::string session = shell_quoted((dir / "s.h5").string());
  ASSERT_EQ(run_tomorig("simulate --sets 2 --ppp 0.02 -o " + session).exit_code, 0);
  const CliResult r = run_tomorig("inspect " + session + " --png " + shell_quoted((dir / "ql").string()) + " --set 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* camera : {"cam0", "cam1", "cam2", "cam3"})
    for (const char* e : {"A", "B"}) {
      const auto file = dir / "ql" / (std::string(camera) + "_set1_" + e + ".png");
      ASSERT_TRUE(std::filesystem::exists(file)) << file;
      EXPECT_NE(r.out.find(file.string()), std::string::npos) << r.out;
      const Image png = storage::read_image(file);
      ASSERT_EQ(png.type(), SampleType::u8);
      EXPECT_EQ(png.width(), 512);
      EXPECT_EQ(png.height(), 512);
      // Particles on a dark background: the stretch leaves most pixels black and the
      // particle peaks white.
      int white = 0, black = 0;
      for (int y = 0; y < png.height(); ++y)
        for (int x = 0; x < png.width(); ++x) {
          const auto v = png.at<std::uint8_t>(x, y);
          white += v == 255;
          black += v == 0;
        }
      EXPECT_GT(white, 0);
      EXPECT_GT(black, png.width() * png.height() / 2);
    }
}

TEST(QuicklookCli, SetOutOfRangeIsBadInput) {
  TempDir dir;
  const std::string session = shell_quoted((dir / "s.h5").string());
  ASSERT_EQ(run_tomorig("simulate --sets 1 --ppp 0.01 -o " + session).exit_code, 0);
  const CliResult r = run_tomorig("inspect " + session + " --png " + shell_quoted((dir / "ql").string()) + " --set 5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--set 5 is out of range"), std::string::npos) << r.err;
}

// Small frames keep this quick; the acceptance size is the default (4 x 2048^2 at 10 Hz).
TEST(QuicklookCli, BenchReportsLossLatenessAndTheQuickLooksCpuTime) {
  TempDir dir;
  const std::string common = "bench quicklook --cameras 2 --side 128 --sets 4 --rate 20 --preview off --publish none "
                             "--folder " + shell_quoted(dir.path().string());
  const CliResult with = run_tomorig(common);
  ASSERT_EQ(with.exit_code, 0) << with.err;
  const nlohmann::json j = nlohmann::json::parse(with.out);
  EXPECT_EQ(j["recorder"]["written"], 4);
  EXPECT_EQ(j["recorder"]["lost"], 0);
  EXPECT_GT(j["recorder"]["ms_per_set"].get<double>(), 0.0);
  const nlohmann::json& q = j["quicklook"];
  EXPECT_EQ(q["analysed"].get<int>() + q["skipped"].get<int>(), 4);
  EXPECT_GE(q["analysed"].get<int>(), 1) << "the newest set is always analysed";
  EXPECT_GT(q["cpu_ms_per_camera_frame"].get<double>(), 0.0);
  EXPECT_GT(q["cpu_share"].get<double>(), 0.0);
  EXPECT_EQ(q["status"]["nice"]["statistics"], 5);
  EXPECT_NE(with.err.find("ms CPU"), std::string::npos) << with.err;

  const CliResult alone = run_tomorig(common + " --quicklook off");
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  const nlohmann::json a = nlohmann::json::parse(alone.out);
  EXPECT_EQ(a["recorder"]["written"], 4);
  EXPECT_TRUE(a["quicklook"].is_null());
  EXPECT_EQ(alone.err.find("quick-look analysed"), std::string::npos) << alone.err;

  const CliResult bad = run_tomorig(common + " --quicklook maybe");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--quicklook maybe"), std::string::npos) << bad.err;
}

// The spray rig's case (reduced here; the full 2560 x 2160 is the default) with the quick-look
// alone: its shadow mode, and the ms per set the lead times quietly (docs/spray.md).
TEST(QuicklookCli, BenchTimesTheSprayQuickLookPerSetWithoutTheRecorder) {
  TempDir dir;
  const CliResult r = run_tomorig("bench quicklook --case spray-thesis --reduced --recorder off --sets 3 --distinct 1 "
                                  "--rate 25 --publish none --folder " + shell_quoted(dir.path().string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["case"], "spray-thesis");
  EXPECT_EQ(j["cameras"], 4);
  EXPECT_EQ(j["width"], 640);
  EXPECT_TRUE(j["recorder"].is_null());
  const nlohmann::json& q = j["quicklook"];
  EXPECT_EQ(q["status"]["mode"], "shadow");
  EXPECT_EQ(q["analysed"].get<int>() + q["skipped"].get<int>(), 3);
  EXPECT_GT(q["cpu_ms_per_set"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(q["period_ms"].get<double>(), 40.0);
  EXPECT_FALSE(std::filesystem::exists(dir / "tomorig-bench-quicklook.h5")) << "no recorder, no file";
  EXPECT_NE(r.err.find("no recorder"), std::string::npos) << r.err;

  const CliResult bad = run_tomorig("bench quicklook --reduced --recorder off --sets 1");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--case spray-thesis"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace tomorig::testing
