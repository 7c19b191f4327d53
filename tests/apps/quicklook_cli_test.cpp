// `tomorig inspect --png`: quick-look PNGs of one set that open in any image viewer.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

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

}  // namespace
}  // namespace tomorig::testing
