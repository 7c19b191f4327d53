// `tomorig run`: the main job on the embedded default rig and on rig files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <csignal>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

TEST(RunCommand, DefaultRigRecordsASimulatedSessionWithTruth) {
  TempDir tmp;
  const auto out = tmp / "run.h5";
  CliResult r = run_tomorig("run --sets 1 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(std::filesystem::exists(out));
  storage::SessionReader session(out);
  EXPECT_EQ(session.set_count(), 1u);
  ASSERT_EQ(session.info().cameras.size(), 4u);
  EXPECT_EQ(session.info().cameras[0].width, 512);
  EXPECT_TRUE(session.has_truth());
  EXPECT_NE(session.info().rig_config_toml.find("tpiv-thesis"), std::string::npos);
  EXPECT_EQ(session.missing_frames(), 0);
}

TEST(RunCommand, MalformedRigFileIsBadInputNamingTheKey) {
  TempDir tmp;
  const auto rig = tmp / "rig.toml";
  write_text(rig, "[[cameras]]\nid = \"cam0\"\npixel_format = \"Mono14\"\n");
  CliResult r = run_tomorig("run --config '" + rig.string() + "' --out '" + (tmp / "x.h5").string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("pixel_format"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(tmp / "x.h5"));
}

TEST(RunCommand, MissingRigFileIsBadUsage) {
  CliResult r = run_tomorig("run --config /nonexistent/rig.toml");
  EXPECT_EQ(r.exit_code, 2);
}

TEST(RunCommand, UnwritableOutputIsBadInputAndLeavesNothingBehind) {
  // A regular file used as the output folder cannot be written even by root.
  TempDir tmp;
  const auto not_a_folder = tmp / "plain-file";
  write_text(not_a_folder, "x");
  CliResult r = run_tomorig("run --sets 1 --out '" + (not_a_folder / "s.h5").string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("plain-file"), std::string::npos) << r.err;
  int entries = 0;
  for ([[maybe_unused]] auto& e : std::filesystem::directory_iterator(tmp.path())) ++entries;
  EXPECT_EQ(entries, 1);  // only the plain file itself
}

}  // namespace
}  // namespace tomorig::testing

// Ctrl-C during `tomorig run` ends the recording between sets with a complete session.
namespace tomorig::testing {
namespace {

// A status address run cannot bind is refused with the options, before a file or a device
// exists; the advice names what run accepts (no allow_remote option exists for --status).
TEST(RunCommand, RefusedStatusEndpointLeavesNoPartialFile) {
  if (!tomorig_built()) GTEST_SKIP() << "tomorig binary not built";
  TempDir tmp;
  const auto out = tmp / "x.h5";
  for (const std::string status : {"tcp://0.0.0.0:45558", "udp://nowhere"}) {
    const CliResult r = run_tomorig("run --sets 1 --status " + status + " --out " + shell_quoted(out.string()));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("--status"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("allow_remote"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << status;
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial")) << status;
  }
}

TEST(RunCommandSignals, SigintLeavesACompleteSessionWithTheSetsRecorded) {
  TempDir dir;
  const auto out = dir / "run.h5";
  TomorigProcess run({"run", "--sets", "500", "-o", out.string()});
  ASSERT_TRUE(run.wait_for_line("recording: set 3/")) << run.err();
  run.send_signal(SIGINT);
  ASSERT_EQ(run.wait(), 0) << run.err();
  EXPECT_NE(run.err().find("stopped by SIGINT"), std::string::npos) << run.err();
  ASSERT_TRUE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  EXPECT_GE(session.set_count(), 3u);
  EXPECT_LT(session.set_count(), 500u);
  EXPECT_EQ(session.truth_set_count(), session.set_count());
}

}  // namespace
}  // namespace tomorig::testing

// The live path of `tomorig run`: trigger device -> simulated cameras -> assembler -> in-process
// stream -> recorder, checked against the simulator, and its faults.
#include <chrono>

#include <zmq.hpp>

#include "../storage/disk_full_tmpfs.h"
#include "tomorig/stream/status.h"

namespace tomorig::testing {
namespace {

TEST(RunCommandLive, FramesAndTruthAreTheSimulatorsBitForBit) {
  TempDir dir;
  const auto reference = dir / "reference.h5";
  const auto out = dir / "run.h5";
  CliResult sim = run_tomorig("simulate --sets 2 -o " + shell_quoted(reference.string()));
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  CliResult r = run_tomorig("run --sets 2 --pace max --status none -o " + shell_quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The status line: sets, rates, queue and per-camera losses.
  EXPECT_NE(r.err.find("recording: set 2/2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("lost frames/incomplete sets: cam0 0/0 cam1 0/0 cam2 0/0 cam3 0/0"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("0 lost frames, 0 incomplete sets"), std::string::npos) << r.out;
  const storage::SessionReader a(reference);
  const storage::SessionReader b(out);
  ASSERT_EQ(b.set_count(), 2u);
  EXPECT_TRUE(b.recording_complete());
  ASSERT_EQ(b.truth_set_count(), 2u);
  for (std::uint64_t k = 0; k < 2; ++k) {
    const FrameSet sa = a.read_set(k), sb = b.read_set(k);
    EXPECT_EQ(sb.dt_ns, sa.dt_ns);
    ASSERT_EQ(sa.cameras.size(), sb.cameras.size());
    for (std::size_t c = 0; c < sa.cameras.size(); ++c)
      for (const Exposure e : {Exposure::A, Exposure::B})
        EXPECT_TRUE(sa.cameras[c][e].image.same_pixels(sb.cameras[c][e].image)) << "set " << k << " camera " << c;
    const storage::TruthSet ta = a.truth_set(k), tb = b.truth_set(k);
    ASSERT_EQ(ta.particles_b.size(), tb.particles_b.size());
    for (std::size_t n = 0; n < ta.particles_b.size(); ++n) EXPECT_EQ(ta.particles_b[n].x, tb.particles_b[n].x);
  }
}

TEST(RunCommandLive, VanishingCameraWithContinueIsCountedAndTheFileIsValid) {
  TempDir dir;
  const auto out = dir / "run.h5";
  CliResult r = run_tomorig("run --sets 5 --pace max --status none --inject-fault cam1:vanish-after=3 "
                            "--on-camera-loss continue -o " + shell_quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("camera cam1 vanished at trigger 3; continuing"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cam1 4/2"), std::string::npos) << r.err;  // 4 lost frames in 2 incomplete sets
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  ASSERT_EQ(session.set_count(), 5u);
  EXPECT_EQ(session.missing_frames(), 4);
  EXPECT_EQ(session.incomplete_sets(), 2);
  EXPECT_FALSE(session.set_record(3).frame_present[1][0]);
  EXPECT_TRUE(session.set_record(3).frame_present[0][0]);
}

TEST(RunCommandLive, VanishingCameraWithStopEndsTheRunAndKeepsAValidFile) {
  TempDir dir;
  const auto out = dir / "run.h5";
  CliResult r = run_tomorig("run --sets 50 --pace max --status none --inject-fault cam2:vanish-after=2 -o " +
                            shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("camera cam2 vanished at trigger 2; stopping the run"), std::string::npos) << r.err;
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  ASSERT_GE(session.set_count(), 3u);  // sets 0 and 1 complete, set 2 flagged without cam2
  EXPECT_LT(session.set_count(), 50u);
  EXPECT_EQ(session.missing_frames(), 2 * static_cast<int>(session.set_count() - 2));
  EXPECT_TRUE(session.set_record(1).frame_present[2][1]);
  EXPECT_FALSE(session.set_record(2).frame_present[2][0]);
}

TEST(RunCommandLive, CameraAbsentAtStartIsNamedAndNothingIsWritten) {
  TempDir dir;
  const auto rig = dir / "rig.toml";
  write_text(rig, "name = \"absent camera\"\n[[cameras]]\nid = \"camX\"\nbackend = \"aravis\"\n"
                  "device_id = \"Aravis-Fake-NOPE\"\n");
  const auto out = dir / "run.h5";
  CliResult r = run_tomorig("run --config " + shell_quoted(rig.string()) + " --sets 2 --status none -o " +
                            shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("camera camX"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Aravis-Fake-NOPE"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

TEST(RunCommandLive, FullDiskStopsTheRecorderSaysSoAndKeepsEverySet) {
  SmallTmpfs disk(30);  // a set of the default rig is 4 MiB of pixels
  if (!disk.available()) GTEST_SKIP() << disk.why();
  const auto out = disk / "run.h5";
  CliResult r = run_tomorig("run --sets 40 --pace max --status none --disk-reserve-mb 4 -o " +
                            shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("recording stopped: the disk holding"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("is full"), std::string::npos) << r.err;
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  EXPECT_GE(session.set_count(), 3u);
  EXPECT_LT(session.set_count(), 40u);
  EXPECT_EQ(session.truth_set_count(), session.set_count());
  EXPECT_EQ(session.missing_frames(), 0);
  for (std::uint64_t k = 0; k < session.set_count(); ++k) EXPECT_EQ(session.read_set(k).cameras.size(), 4u);
}

TEST(RunCommandLive, StatusSocketPublishesTheFiguresAsJson) {
  TempDir dir;
  TomorigProcess run({"run", "--sets", "60", "--status", "tcp://127.0.0.1:*", "-o", (dir / "s.h5").string()});
  const std::string marker = "run: status JSON on ";
  const auto line = run.wait_for_line(marker);
  ASSERT_TRUE(line) << run.err();
  const std::string endpoint = line->substr(line->find(marker) + marker.size());
  zmq::context_t context(1);
  stream::SocketOptions options = stream::status_socket_options(endpoint);
  options.endpoint.bind = false;
  options.timeout = std::chrono::milliseconds(10000);
  stream::StatusSubscriber subscriber(context, options);
  const auto status = subscriber.receive();  // one update a set at first, then one a second
  ASSERT_TRUE(status) << "no status message on " << endpoint;
  EXPECT_EQ(status->state, "running");
  ASSERT_EQ(status->cameras.size(), 4u);
  EXPECT_EQ(status->cameras[3].camera_id, "cam3");
  EXPECT_EQ(status->frames_lost, 0u);
  run.send_signal(SIGINT);
  EXPECT_EQ(run.wait(), 0) << run.err();
}

}  // namespace
}  // namespace tomorig::testing
