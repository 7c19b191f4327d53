// End to end: the tomorig binary's inspect and import commands on files made here.
// Skipped when the binary has not been built (it links every module).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_runner.h"
#include "storage_test_support.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {
namespace {
namespace fs = std::filesystem;
using testing::TempDir;
using testing::test_camera;
using testing::test_set;

using RunResult = tomorig::testing::CliResult;
std::string quote(const std::string& s) { return tomorig::testing::shell_quoted(s); }

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig::testing::tomorig_built()) GTEST_SKIP() << "tomorig binary not built: " << TOMORIG_BINARY;
  }

  RunResult run(const std::string& args) { return tomorig::testing::run_tomorig(args); }

  TempDir dir_;
};

TEST_F(CliTest, InspectJsonDescribesTheSession) {
  const fs::path path = dir_ / "s.h5";
  const std::vector<SessionCamera> cameras{test_camera("cam0", 32, 24, PixelFormat::Mono16),
                                           test_camera("cam1", 16, 8, PixelFormat::Mono8)};
  SessionInfo info;
  info.cameras = cameras;
  {
    SessionWriter writer(path, info, testing::writer_options(Compression::bitshuffle_lz4));
    for (std::uint64_t s = 0; s < 3; ++s) {
      FrameSet set = test_set(cameras, s);
      if (s == 1) set.cameras[0].a.image = Image();
      writer.append(set);
    }
    writer.finish();
  }
  const RunResult r = run("inspect --json " + quote(path.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["cameras"].size(), 2u);
  EXPECT_EQ(j["cameras"][0]["id"], "cam0");
  EXPECT_EQ(j["cameras"][0]["width"], 32);
  EXPECT_EQ(j["cameras"][0]["height"], 24);
  EXPECT_EQ(j["cameras"][0]["pixel_format"], "Mono16");
  EXPECT_EQ(j["cameras"][1]["pixel_format"], "Mono8");
  EXPECT_EQ(j["sets"], 3);
  EXPECT_EQ(j["missing_frames"], 1);
  EXPECT_EQ(j["incomplete_sets"], 1);
  EXPECT_EQ(j["truth"], false);
  EXPECT_EQ(j["compression"], "bitshuffle-lz4");
  EXPECT_EQ(j["dt_ns"]["min"], 100000);
  EXPECT_EQ(j["dt_ns"]["max"], 100002);
  EXPECT_DOUBLE_EQ(j["time_span_s"].get<double>(), 0.2);
  EXPECT_FALSE(j["software_version"].get<std::string>().empty());
  EXPECT_FALSE(j["created_utc"].get<std::string>().empty());

  const RunResult text = run("inspect " + quote(path.string()));
  EXPECT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("cam1"), std::string::npos) << text.out;
}

// A damaged file's free text (here the version attribute, as a flipped bit of the fuzz left it:
// not UTF-8, and an escape sequence) is shown escaped and never ends `inspect --json` with
// nlohmann's raw "invalid UTF-8" exception (exit 1 before the fix).
TEST_F(CliTest, InspectShowsTextThatIsNotUtf8WithoutFailing) {
  const fs::path path = dir_ / "s.h5";
  const std::vector<SessionCamera> cameras{test_camera("cam0", 32, 24, PixelFormat::Mono16)};
  SessionInfo info;
  info.cameras = cameras;
  info.software_version = "0.1.0+gc3f80d\xb6\x1b[2J";
  {
    SessionWriter writer(path, info, testing::writer_options(Compression::none));
    writer.append(test_set(cameras, 0));
    writer.finish();
  }
  const RunResult j = run("inspect --json " + quote(path.string()));
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const std::string version = nlohmann::json::parse(j.out)["software_version"].get<std::string>();
  EXPECT_EQ(version, "0.1.0+gc3f80d\xef\xbf\xbd\x1b[2J");  // U+FFFD for the byte that is not UTF-8

  const RunResult text = run("inspect " + quote(path.string()));
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("0.1.0+gc3f80d\\xb6\\x1b[2J"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find('\x1b'), std::string::npos) << "an escape sequence reached the terminal";
}

TEST_F(CliTest, InspectCorruptFileExitsWithBadInput) {
  const fs::path path = dir_ / "s.h5";
  testing::write_test_session(path, {test_camera("cam0", 32, 24, PixelFormat::Mono16)}, 3);
  fs::resize_file(path, fs::file_size(path) / 2);
  const RunResult r = run("inspect --json " + quote(path.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("corrupt or truncated"), std::string::npos) << r.err;

  const RunResult missing = run("inspect " + quote((dir_ / "nope.h5").string()));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("does not exist"), std::string::npos) << missing.err;
}

TEST_F(CliTest, ImportThenInspect) {
  for (const char* cam : {"cam0", "cam1"}) {
    fs::create_directories(dir_ / cam);
    for (const char* e : {"a", "b"})
      ASSERT_TRUE(cv::imwrite((dir_ / cam / (std::string("im00001") + e + ".png")).string(),
                              cv::Mat(12, 20, CV_8UC1, cv::Scalar(7))));
  }
  const fs::path out = dir_ / "imported.h5";
  const std::string cams = " --camera " + quote("cam0=" + (dir_ / "cam0" / "im*.png").string()) + " --camera " +
                           quote("cam1=" + (dir_ / "cam1" / "im*.png").string());
  const RunResult r = run("import" + cams + " --dt-us 50 --pixel-pitch-um 6.5 --out " + quote(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("imported 1 set from 2 cameras"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("--dt-us is deprecated"), std::string::npos) << r.err;  // the old spelling still works

  const auto j = nlohmann::json::parse(run("inspect --json " + quote(out.string())).out);
  EXPECT_EQ(j["sets"], 1);
  EXPECT_EQ(j["cameras"][1]["width"], 20);
  EXPECT_EQ(j["cameras"][1]["height"], 12);
  EXPECT_EQ(j["cameras"][1]["pixel_pitch_um"], 6.5);
  EXPECT_EQ(j["dt_ns"]["min"], 50000);

  // Again without --overwrite: the file exists, bad input.
  const RunResult again = run("import" + cams + " --dt 50us --out " + quote(out.string()));
  EXPECT_EQ(again.exit_code, 2);
  EXPECT_NE(again.err.find("already exists"), std::string::npos) << again.err;

  const RunResult no_dt = run("import" + cams + " --out " + quote((dir_ / "x.h5").string()));
  EXPECT_EQ(no_dt.exit_code, 2);
  EXPECT_NE(no_dt.err.find("--dt with its unit"), std::string::npos) << no_dt.err;
}

}  // namespace
}  // namespace tomorig::storage
