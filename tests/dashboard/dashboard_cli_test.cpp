// The dashboard through the product: `tomorig run --http` serves it while recording (several
// pages watching, the recorder losing nothing), `tomorig preview --session S.h5 --http` serves a
// recorded run's quick-look history, and bad use is refused with exit code 2 before any file
// exists. Processes synchronise on printed lines and exits, never on sleeps.
#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <regex>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "child_process.h"
#include "cli_runner.h"
#include "event_stream.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

constexpr double kTruePpp = 0.05;  // the default rig's [simulation] ppp

// The port of the "dashboard on http://127.0.0.1:PORT/" line a command printed.
int dashboard_port(TomorigProcess& process) {
  const auto line = process.wait_for_line("dashboard on http://");
  if (!line) return -1;
  std::smatch m;
  if (!std::regex_search(*line, m, std::regex("http://127\\.0\\.0\\.1:(\\d+)/"))) return -1;
  return std::stoi(m[1]);
}

class DashboardCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  }
};

TEST_F(DashboardCli, RunServesTheDashboardAndRecordsEverySetWhilePagesWatch) {
  TempDir dir;
  const fs::path session = dir / "s.h5";
  constexpr int kSets = 30;
  TomorigProcess run({"run", "--sets", std::to_string(kSets), "--status", "ipc://" + (dir / "st").string(), "--preview",
                      "ipc://" + (dir / "ql").string(), "--http", "127.0.0.1:0", "-o", session.string()});
  const int port = dashboard_port(run);
  ASSERT_GT(port, 0) << run.err();
  std::vector<std::unique_ptr<EventStream>> pages;
  for (int i = 0; i < 3; ++i) pages.push_back(std::make_unique<EventStream>(port));
  for (auto& page : pages) {
    EXPECT_TRUE(page->wait_for("event: quicklook", 60s)) << page->text().substr(0, 500);
    EXPECT_TRUE(page->wait_for("event: status", 30s));
  }
  httplib::Client client("127.0.0.1", port);
  const auto state = client.Get("/api/state");
  ASSERT_TRUE(state);
  const json now = json::parse(state->body);
  ASSERT_EQ(now.at("quicklook").at("cameras").size(), 4u);
  const json& ppp = now.at("quicklook").at("cameras")[0].at("statistics").at("a").at("particles").at("ppp");
  EXPECT_NEAR(ppp.at("value").get<double>(), kTruePpp, 0.1 * kTruePpp);
  EXPECT_EQ(now.at("info").at("trigger_plan").at("dt_us"), 100.0) << "the default rig's plan";
  EXPECT_EQ(now.at("status").at("cameras").size(), 4u);
  const auto thumb = client.Get("/image/cam1/a");
  ASSERT_TRUE(thumb);
  EXPECT_EQ(thumb->status, 200);

  ASSERT_EQ(run.wait(), 0) << run.err();
  const storage::SessionReader reader(session);
  EXPECT_EQ(reader.set_count(), static_cast<std::uint64_t>(kSets)) << "every set recorded while pages watched";
  EXPECT_EQ(reader.missing_frames(), 0);
}

TEST_F(DashboardCli, PreviewSessionServesTheStoredHistory) {
  TempDir dir;
  const fs::path session = dir / "s.h5";
  const CliResult run = run_tomorig("run --sets 12 --status none --preview " +
                                    shell_quoted("ipc://" + (dir / "ql").string()) + " -o " + shell_quoted(session.string()));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const CliResult inspect = run_tomorig("inspect --json " + shell_quoted(session.string()));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const json stored = json::parse(inspect.out).at("quicklook");

  TomorigProcess preview({"preview", "--session", session.string(), "--http", "127.0.0.1:0"});
  const int port = dashboard_port(preview);
  ASSERT_GT(port, 0) << preview.err();
  httplib::Client client("127.0.0.1", port);
  const auto history = client.Get("/api/history");
  ASSERT_TRUE(history);
  ASSERT_EQ(history->status, 200);
  const json h = json::parse(history->body);
  EXPECT_EQ(h.at("sets"), stored.at("sets"));
  EXPECT_EQ(h.at("history").size(), stored.at("history").size());
  EXPECT_EQ(h.at("history"), stored.at("history")) << "the rows inspect reads";
  EXPECT_NEAR(h.at("cameras")[0].at("ppp").at("median").get<double>(), kTruePpp, 0.1 * kTruePpp);
  const auto state = client.Get("/api/state");
  ASSERT_TRUE(state);
  const json info = json::parse(state->body).at("info");
  EXPECT_EQ(info.at("mode"), "session");
  EXPECT_EQ(info.at("sets_recorded"), 12);
  EXPECT_EQ(info.at("trigger_plan").at("dt_us"), 100.0) << "from the rig stored in the session";
  EventStream page(port);
  EXPECT_TRUE(page.wait_for("event: history", 10s)) << page.text().substr(0, 300);

  preview.send_signal(SIGINT);
  EXPECT_EQ(preview.wait(), 0) << preview.err();
}

// `tomorig replay --http`: the dashboard of a replayed session, fed by the replay's own quick-look,
// with the trigger plan of the rig stored in the session.
TEST_F(DashboardCli, ReplayServesTheDashboardOfTheSetsItSends) {
  TempDir dir;
  const fs::path source = dir / "src.h5";
  ASSERT_EQ(run_tomorig("run --sets 12 --status none -o " + shell_quoted(source.string())).exit_code, 0);
  TomorigProcess replay({"replay", source.string(), "--to", "tcp://127.0.0.1:*", "--rate", "4", "--preview",
                         "ipc://" + (dir / "ql").string(), "--http", "127.0.0.1:0"});
  const int port = dashboard_port(replay);  // printed before the stream's line
  ASSERT_GT(port, 0) << replay.err();
  const auto first = replay.wait_for_line("sending on");
  ASSERT_TRUE(first) << replay.err();
  const std::string to = first->substr(first->find("sending on ") + 11, first->find(',') - first->find("sending on ") - 11);
  EventStream page(port);
  TomorigProcess record({"record", "--from", to, "-o", (dir / "copy.h5").string(), "--idle-timeout", "60"});
  EXPECT_TRUE(page.wait_for("event: quicklook", 60s)) << page.text().substr(0, 500) << replay.err();
  httplib::Client client("127.0.0.1", port);
  const auto state = client.Get("/api/state");
  ASSERT_TRUE(state);
  const json now = json::parse(state->body);
  EXPECT_EQ(now.at("info").at("mode"), "live");
  EXPECT_EQ(now.at("info").at("source"), source.string());
  EXPECT_EQ(now.at("info").at("trigger_plan").at("dt_us"), 100.0) << "from the rig stored in the session";
  ASSERT_EQ(now.at("quicklook").at("cameras").size(), 4u);
  const json& ppp = now.at("quicklook").at("cameras")[0].at("statistics").at("a").at("particles").at("ppp");
  EXPECT_NEAR(ppp.at("value").get<double>(), kTruePpp, 0.1 * kTruePpp);
  ASSERT_EQ(record.wait(), 0) << record.err();
  ASSERT_EQ(replay.wait(), 0) << replay.err();
  EXPECT_EQ(storage::SessionReader(dir / "copy.h5").set_count(), 12u);
}

TEST_F(DashboardCli, BadUseIsRefusedBeforeAnyFile) {
  TempDir dir;
  const fs::path out = dir / "s.h5";
  const CliResult remote = run_tomorig("run --sets 2 --status none --http 0.0.0.0:0 -o " + shell_quoted(out.string()));
  EXPECT_EQ(remote.exit_code, 2);
  EXPECT_NE(remote.err.find("--http-allow-remote"), std::string::npos) << remote.err;
  EXPECT_FALSE(fs::exists(out)) << "refused before the session file";
  const CliResult bad_address = run_tomorig("run --sets 2 --status none --http localhost:http -o " + shell_quoted(out.string()));
  EXPECT_EQ(bad_address.exit_code, 2);
  EXPECT_NE(bad_address.err.find("HOST:PORT"), std::string::npos) << bad_address.err;
  const CliResult short_token =
      run_tomorig("run --sets 2 --status none --http 127.0.0.1:0 --http-token abc -o " + shell_quoted(out.string()));
  EXPECT_EQ(short_token.exit_code, 2);
  EXPECT_NE(short_token.err.find("at least 16"), std::string::npos) << short_token.err;
  EXPECT_FALSE(fs::exists(out));

  const fs::path plain = dir / "plain.h5";
  ASSERT_EQ(run_tomorig("simulate --sets 2 -o " + shell_quoted(plain.string())).exit_code, 0);
  const CliResult no_history = run_tomorig("preview --session " + shell_quoted(plain.string()) + " --http 127.0.0.1:0");
  EXPECT_EQ(no_history.exit_code, 2);
  EXPECT_NE(no_history.err.find("no quick-look history"), std::string::npos) << no_history.err;
  const CliResult no_http = run_tomorig("preview --session " + shell_quoted(plain.string()));
  EXPECT_EQ(no_http.exit_code, 2);
  EXPECT_NE(no_http.err.find("needs --http"), std::string::npos) << no_http.err;
}

}  // namespace
}  // namespace tomorig::testing

namespace tomorig::testing {
namespace {

// The rig file's [dashboard]: its address serves `--http` without a value; a remote one needs
// allow_remote; bad keys are named.
TEST_F(DashboardCli, RigFileSetsTheAddressAndGuardsRemoteOnes) {
  TempDir dir;
  const CliResult rig = run_tomorig("config default");
  ASSERT_EQ(rig.exit_code, 0) << rig.err;
  const fs::path local = dir.write("local.toml", rig.out + "\n[dashboard]\nhttp = \"127.0.0.1:0\"\n");
  TomorigProcess run({"run", "--config", local.string(), "--sets", "3", "--status", "none", "--preview",
                      "ipc://" + (dir / "ql").string(), "--http", "-o", (dir / "a.h5").string()});
  EXPECT_GT(dashboard_port(run), 0) << run.err();
  EXPECT_EQ(run.wait(), 0) << run.err();

  const fs::path remote = dir.write("remote.toml", rig.out + "\n[dashboard]\nhttp = \"0.0.0.0:0\"\n");
  const CliResult refused = run_tomorig("run --config " + shell_quoted(remote.string()) +
                                        " --sets 2 --status none --http -o " + shell_quoted((dir / "b.h5").string()));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_NE(refused.err.find("refusing to serve the dashboard on 0.0.0.0:0"), std::string::npos) << refused.err;
  EXPECT_FALSE(fs::exists(dir / "b.h5"));

  const fs::path bad = dir.write("bad.toml", rig.out + "\n[dashboard]\nhttp = \"somewhere\"\n");
  const CliResult malformed = run_tomorig("run --config " + shell_quoted(bad.string()) +
                                          " --sets 2 --status none --http -o " + shell_quoted((dir / "c.h5").string()));
  EXPECT_EQ(malformed.exit_code, 2);
  EXPECT_NE(malformed.err.find("[dashboard] http"), std::string::npos) << malformed.err;

  const fs::path unknown = dir.write("unknown.toml", rig.out + "\n[dashboard]\nport = 8080\n");
  const CliResult check = run_tomorig("config check " + shell_quoted(unknown.string()));
  EXPECT_EQ(check.exit_code, 2);
  EXPECT_NE(check.err.find("dashboard.port"), std::string::npos) << check.err;
}

}  // namespace
}  // namespace tomorig::testing
