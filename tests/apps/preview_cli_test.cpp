// The quick-look through the product (issue 16, item 5): `tomorig preview` attached to
// `tomorig run --preview` on the default rig shows live numbers (checked against the
// simulator's truth), its JSON lines carry the documented fields, snapshots are written, the
// numbers are stored with the session for `inspect`, a stalled viewer never slows the recorder,
// and `tomorig replay --preview` publishes too. Processes synchronise on printed lines and
// exits, never on sleeps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <zmq.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/storage/session_file.h"
#include "tomorig/stream/preview.h"

namespace tomorig::testing {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;

// The default rig's truth: [simulation] ppp = 0.05, the tpiv-thesis slab z in [-1.5, 1.5] mm lit
// uniformly (simulators/case_tpiv_thesis.cpp), so the sheet is 3 mm thick at z = 0.
constexpr double kTruePpp = 0.05;
constexpr double kSheetThicknessMm = 3.0;
constexpr double kPreviewSliceMm = 2 * 0.0195;  // the preview grid's voxels: the rig's, binned 2 x 2

std::string ipc_endpoint(const TempDir& dir, const char* name) { return "ipc://" + (dir / name).string(); }

std::vector<json> json_lines(const std::string& text) {
  std::vector<json> out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty()) out.push_back(json::parse(line));
  return out;
}

class PreviewCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
};

TEST_F(PreviewCli, AttachedToRunShowsLiveNumbersStoredForInspect) {
  TempDir dir;
  const std::string endpoint = ipc_endpoint(dir, "ql");
  const fs::path snaps = dir / "snaps";
  TomorigProcess preview({"preview", "--from", endpoint, "--json", "--count", "4", "--timeout", "120", "--png",
                          snaps.string(), "--png-interval", "0"});
  ASSERT_TRUE(preview.wait_for_line("listening")) << preview.err();

  const fs::path session = dir / "s.h5";
  const CliResult run = run_tomorig("run --sets 20 --status none --preview " + shell_quoted(endpoint) + " -o " +
                                    shell_quoted(session.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("quick-look results on " + endpoint), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("run: quick-look:"), std::string::npos) << run.err;
  ASSERT_EQ(preview.wait(), 0) << preview.err();

  // One JSON line per set, with the documented fields and numbers near the truth.
  const std::vector<json> lines = json_lines(preview.out());
  ASSERT_EQ(lines.size(), 4u) << preview.out();
  std::uint64_t previous = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const json& j = lines[i];
    EXPECT_EQ(j.at("type"), "tomorig.quicklook");
    EXPECT_EQ(j.at("version"), 1);
    const auto set = j.at("set").get<std::uint64_t>();
    if (i > 0) EXPECT_GT(set, previous) << "sets arrive in order";
    previous = set;
    EXPECT_EQ(j.at("dt_ns"), 100'000) << "the default rig's 100 us";
    EXPECT_TRUE(j.at("flag").is_string());
    EXPECT_FALSE(j.contains("images")) << "part numbers mean nothing in a text line";
    ASSERT_EQ(j.at("cameras").size(), 4u);
    for (std::size_t c = 0; c < 4; ++c) {
      const json& cam = j.at("cameras")[c];
      EXPECT_EQ(cam.at("id"), "cam" + std::to_string(c));
      const json& particles = cam.at("statistics").at("a").at("particles");
      EXPECT_NEAR(particles.at("ppp").at("value").get<double>(), kTruePpp, 0.1 * kTruePpp) << j.dump();
      EXPECT_EQ(particles.at("ppp").at("flag"), "green");
      EXPECT_TRUE(particles.at("diameter_px").at("value").is_number());
      EXPECT_TRUE(cam.at("statistics").at("b").at("saturation").at("fraction").contains("flag"));
      EXPECT_TRUE(cam.at("statistics").at("energy_balance").at("value").is_number());
      EXPECT_TRUE(cam.at("dt_check").contains("displacement_px"));
      EXPECT_EQ(cam.at("dt_check").at("windows").size(), 16u);
    }
    const json& counts = j.at("counts");
    for (const char* key : {"analysed", "skipped", "previews", "previews_skipped", "published", "stored"})
      EXPECT_TRUE(counts.contains(key)) << key;
    EXPECT_TRUE(j.contains("preview") && j.contains("drift"));
  }

  // Snapshots with the images the messages carried.
  for (const json& j : lines) {
    const fs::path file = snaps / fmt::format("set_{:06}.png", j.at("set").get<std::uint64_t>());
    ASSERT_TRUE(fs::exists(file)) << file;
    const Image png = storage::read_image(file);
    EXPECT_EQ(png.type(), SampleType::u8);
    EXPECT_GT(png.width(), 4 * 128) << "four camera thumbnails side by side";
  }

  // Stored with the session: inspect shows the run's history, the sheet where the light was.
  const CliResult inspect = run_tomorig("inspect --json " + shell_quoted(session.string()));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const json history = json::parse(inspect.out).at("quicklook");
  EXPECT_GE(history.at("sets").get<std::uint64_t>(), 4u);
  EXPECT_LE(history.at("last_set").get<std::uint64_t>(), 19u);
  EXPECT_GE(history.at("previews").get<std::uint64_t>(), 1u) << "the last set's preview at least";
  const json& position = history.at("sheet").at("position_mm");
  EXPECT_NEAR(position.at("median").get<double>(), 0.0, kPreviewSliceMm);
  EXPECT_NEAR(history.at("sheet").at("thickness_mm").at("median").get<double>(), kSheetThicknessMm,
              0.03 * kSheetThicknessMm);
  EXPECT_NEAR(history.at("cameras")[0].at("ppp").at("median").get<double>(), kTruePpp, 0.1 * kTruePpp);
  EXPECT_EQ(history.at("history").size(), history.at("sets").get<std::size_t>());
  const CliResult text = run_tomorig("inspect " + shell_quoted(session.string()));
  EXPECT_NE(text.out.find("quick-look   "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("sheet      at"), std::string::npos) << text.out;
}

TEST_F(PreviewCli, StalledSubscriberNeverSlowsTheRecorder) {
  TempDir dir;
  const std::string endpoint = ipc_endpoint(dir, "ql");
  // A viewer that connects and then reads nothing while the run goes on.
  zmq::context_t context(1);
  stream::SocketOptions options = stream::preview_socket_options(endpoint);
  options.endpoint.bind = false;
  options.timeout = std::chrono::milliseconds(50);
  stream::PreviewSubscriber stalled(context, options);

  constexpr int kSets = 40;
  const fs::path session = dir / "s.h5";
  const CliResult run = run_tomorig(fmt::format("run --sets {} --status none --preview {} -o {}", kSets,
                                                shell_quoted(endpoint), shell_quoted(session.string())));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find(fmt::format("{} sets x 4 cameras", kSets)), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("0 lost frames, 0 incomplete sets"), std::string::npos) << run.out;
  const storage::SessionReader reader(session);
  EXPECT_EQ(reader.set_count(), static_cast<std::uint64_t>(kSets)) << "every set recorded";
  EXPECT_EQ(reader.missing_frames(), 0);

  // The publisher dropped what the stalled viewer could not take, and said so.
  const auto at = run.err.find("messages published on " + endpoint + ", ");
  ASSERT_NE(at, std::string::npos) << run.err;
  const std::string rest = run.err.substr(at);
  const auto dropped = std::stoull(rest.substr(rest.find(", ") + 2));
  EXPECT_GT(dropped, 0u) << run.err;
  // What the viewer holds is whole quick-look messages, far fewer than were published.
  int received = 0;
  while (auto m = stalled.receive_message()) {
    EXPECT_EQ(json::parse(m->json).at("type").get<std::string>().rfind("tomorig.", 0), 0u);
    ++received;
  }
  EXPECT_LT(received, kSets);
}

TEST_F(PreviewCli, ReplayPublishesTheQuickLookOfTheSetsItSends) {
  TempDir dir;
  const fs::path source = dir / "src.h5";
  ASSERT_EQ(run_tomorig("simulate --sets 8 --ppp 0.03 -o " + shell_quoted(source.string())).exit_code, 0);
  const std::string endpoint = ipc_endpoint(dir, "ql");
  TomorigProcess preview({"preview", "--from", endpoint, "--count", "2", "--timeout", "120"});
  ASSERT_TRUE(preview.wait_for_line("listening")) << preview.err();
  TomorigProcess replay({"replay", source.string(), "--to", "tcp://127.0.0.1:*", "--rate", "4", "--preview", endpoint});
  const auto first = replay.wait_for_line("sending on");
  ASSERT_TRUE(first) << replay.err();
  const std::string to = first->substr(first->find("sending on ") + 11, first->find(',') - first->find("sending on ") - 11);
  const CliResult record = run_tomorig("record --from " + to + " -o " + shell_quoted((dir / "copy.h5").string()) +
                                       " --sets 8 --idle-timeout 60");
  ASSERT_EQ(record.exit_code, 0) << record.err;
  ASSERT_EQ(replay.wait(), 0) << replay.err();
  EXPECT_NE(replay.err().find("replay: quick-look:"), std::string::npos) << replay.err();
  ASSERT_EQ(preview.wait(), 0) << preview.err();
  // Not a terminal: one plain line per set with the numbers.
  const std::string out = preview.out();
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
  EXPECT_NE(out.find("cam0 ppp 0.0"), std::string::npos) << out;
  EXPECT_NE(out.find("d_tau"), std::string::npos) << out;
}

TEST_F(PreviewCli, BadUseIsNamed) {
  TempDir dir;
  // Nothing publishes: --timeout ends it with a runtime error that says what to check.
  const CliResult lonely =
      run_tomorig("preview --from " + shell_quoted(ipc_endpoint(dir, "nobody")) + " --timeout 0.5 --count 1");
  EXPECT_EQ(lonely.exit_code, 1);
  EXPECT_NE(lonely.err.find("no quick-look results arrived"), std::string::npos) << lonely.err;

  // Snapshots are never replaced without --overwrite.
  const fs::path snaps = dir / "snaps";
  fs::create_directories(snaps);
  { std::ofstream(snaps / "set_000001.png") << "x"; }
  const CliResult kept = run_tomorig("preview --from " + shell_quoted(ipc_endpoint(dir, "x")) + " --png " +
                                     shell_quoted(snaps.string()) + " --timeout 0.5");
  EXPECT_EQ(kept.exit_code, 2);
  EXPECT_NE(kept.err.find("--overwrite"), std::string::npos) << kept.err;

  // --preview adds a quicklook stage: naming one with --stage too is refused before the rig runs.
  const CliResult twice = run_tomorig("run --sets 1 --status none --preview --stage quicklook -o " +
                                      shell_quoted((dir / "s.h5").string()));
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("either --preview or"), std::string::npos) << twice.err;
  EXPECT_FALSE(fs::exists(dir / "s.h5"));
}

}  // namespace
}  // namespace tomorig::testing
