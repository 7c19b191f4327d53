// `tomorig run` on real GenICam transport: four Aravis GigE Vision fake cameras, each a separate
// arv-fake-gv-camera-0.8 process on its own loopback address (GVA 127.0.0.1 ... GVD 127.0.0.4),
// software-triggered twice per set (frame_mode "two_triggers"). The fake is a single-frame
// camera: it answers one software trigger with one frame, looks for a pending trigger only
// every 40 ms (its 25 Hz trigger rate, so its "readout" is 40 ms), stamps frames with the host's
// real-time clock and numbers them with 16-bit ids that wrap.
//
// Everything goes through the product: a rig file and `tomorig run`. Needs root (to add the
// loopback addresses) and aravis-tools (scripts/apt-packages.txt); skipped, saying why, without.
// The full acceptance run (200 sets, a camera killed at set 50) is in docs/acquisition.md;
// here the same rig runs fewer sets to stay fast.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.h"
#include "cli_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kFakes = 4;
const char* const kAddresses[kFakes] = {"127.0.0.1", "127.0.0.2", "127.0.0.3", "127.0.0.4"};
const char* const kSerials[kFakes] = {"GVA", "GVB", "GVC", "GVD"};
const char* const kCameraIds[kFakes] = {"camA", "camB", "camC", "camD"};
constexpr const char* kFakeBinary = "/usr/bin/arv-fake-gv-camera-0.8";

// The rig of docs/acquisition.md ("Worked example: four GigE fake cameras").
std::string rig_toml(const std::string& frame_mode, double dt_us = 80000) {
  std::ostringstream rig;
  rig << "name = \"four GigE fakes, two triggers a set\"\n";
  for (int c = 0; c < kFakes; ++c)
    rig << "\n[[cameras]]\nid = \"" << kCameraIds[c] << "\"\nbackend = \"aravis\"\ndevice_id = \"" << kAddresses[c]
        << "\"\npixel_format = \"Mono8\"\nframe_mode = \"" << frame_mode << "\"\n[cameras.roi]\nwidth = 64\nheight = 48\n";
  rig << "\n[trigger]\nbackend = \"simulated\"\nrate_hz = 5\ndt_us = " << dt_us << "\n"
      << "\n[trigger.camera]\nexposure_a_us = 1000\nreadout_us = 40000\nframe_time_tolerance_us = 25000\n"
      << "exposure_b_us = 100000  # only read in hardware mode: a frame B long enough for the 80 ms dt\n";
  return rig.str();
}

// The summary line's loss count, as the file has it.
std::string fmt_lost(const storage::SessionReader& session) {
  return std::to_string(session.missing_frames()) + " lost frames, " + std::to_string(session.incomplete_sets()) +
         " incomplete sets";
}

// The frames a camera delivered, from the last status line ("camA connected 50 frames, ..."):
// every frame that reached tomorig, including pairs the pair check dropped afterwards.
long frames_delivered(const std::string& err, const std::string& camera) {
  std::size_t best = std::string::npos;
  for (const char* state : {" connected ", " DISCONNECTED "}) {
    const std::size_t at = err.rfind(camera + state);
    if (at != std::string::npos && (best == std::string::npos || at > best)) best = at;
  }
  if (best == std::string::npos) return -1;
  const std::size_t number = err.find_first_of("0123456789", best + camera.size());
  return number == std::string::npos ? -1 : std::atol(err.c_str() + number);
}

bool run_quietly(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()) == 0; }

// Whether a UDP socket is bound to `address`:3956 (GVCP), from /proc/net/udp ("0100007F:0F74").
bool gvcp_port_bound(const std::string& address) {
  unsigned a = 0, b = 0, c = 0, d = 0;
  std::sscanf(address.c_str(), "%u.%u.%u.%u", &a, &b, &c, &d);
  char wanted[32];
  std::snprintf(wanted, sizeof wanted, "%02X%02X%02X%02X:0F74", d, c, b, a);
  std::ifstream udp("/proc/net/udp");
  std::string line;
  while (std::getline(udp, line))
    if (line.find(wanted) != std::string::npos) return true;
  return false;
}

class GigEFakeRig : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (geteuid() != 0 || access(kFakeBinary, X_OK) != 0) return;
    // The acquisition suite's fakes use the same addresses and port: take turns.
    lock_fd_ = ::open("/tmp/tomorig-gige-fake-test.lock", O_CREAT | O_RDWR, 0644);
    if (lock_fd_ >= 0) ::flock(lock_fd_, LOCK_EX);
    for (int c = 1; c < kFakes; ++c) {
      const std::string address = kAddresses[c];
      added_[c] = !run_quietly("ip -4 addr show dev lo | grep -q 'inet " + address + "/'") &&
                  run_quietly("ip addr add " + address + "/8 dev lo");
    }
  }
  static void TearDownTestSuite() {
    for (int c = 1; c < kFakes; ++c) {
      if (added_[c]) run_quietly(std::string("ip addr del ") + kAddresses[c] + "/8 dev lo");
      added_[c] = false;
    }
    if (lock_fd_ >= 0) ::close(lock_fd_);
    lock_fd_ = -1;
  }

  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "needs root to add the loopback addresses 127.0.0.2-4 of the fake cameras";
    if (access(kFakeBinary, X_OK) != 0)
      GTEST_SKIP() << kFakeBinary << " is missing: install aravis-tools (scripts/apt-packages.txt)";
    if (!tomorig_built()) GTEST_SKIP() << "the tomorig binary is not built";
    for (int c = 0; c < kFakes; ++c) {
      ASSERT_FALSE(gvcp_port_bound(kAddresses[c])) << "something already listens on " << kAddresses[c] << ":3956";
      fakes_[c] = fork();
      ASSERT_GE(fakes_[c], 0);
      if (fakes_[c] == 0) {
        const int null = ::open("/dev/null", O_RDWR);
        dup2(null, 0), dup2(null, 1), dup2(null, 2);
        execl(kFakeBinary, kFakeBinary, "-i", kAddresses[c], "-s", kSerials[c], static_cast<char*>(nullptr));
        _exit(127);
      }
    }
    // Ready when each fake's GVCP socket is bound (a condition, polled; not a fixed sleep).
    const auto give_up = Clock::now() + std::chrono::seconds(10);
    for (int c = 0; c < kFakes; ++c) {
      while (!gvcp_port_bound(kAddresses[c]) && Clock::now() < give_up) usleep(10'000);
      ASSERT_TRUE(gvcp_port_bound(kAddresses[c])) << "fake " << kSerials[c] << " did not start on " << kAddresses[c];
    }
    rig_ = dir_ / "rig.toml";
  }

  void TearDown() override {
    for (auto& pid : fakes_) kill_fake(pid, SIGINT);
  }

  static void kill_fake(pid_t& pid, int sig) {
    if (pid <= 0) return;
    ::kill(pid, sig);
    int status = 0;
    // SIGINT: the fake leaves its 1 s sleep loop; SIGKILL if it does not within 3 s.
    for (int i = 0; i < 300 && waitpid(pid, &status, WNOHANG) == 0; ++i) usleep(10'000);
    if (waitpid(pid, &status, WNOHANG) == 0) {
      ::kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
    }
    pid = -1;
  }

  void write_rig(const std::string& text) { std::ofstream(rig_) << text; }

  inline static bool added_[kFakes] = {};
  inline static int lock_fd_ = -1;
  pid_t fakes_[kFakes] = {-1, -1, -1, -1};
  TempDir dir_;
  std::filesystem::path rig_;
};

// Each pair must come from one trigger event: by every camera's own clock B - A is the plan's
// 80 ms within the 25 ms tolerance (the fake answers a trigger 0-40 ms late), and frame A sits at
// the same place relative to its own trigger in every set (a frame of the next or previous event
// would be 200 ms off).
void expect_pairs_from_their_own_events(const storage::SessionReader& session, int camera) {
  std::vector<std::int64_t> offsets;
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord r = session.set_record(k);
    if (!r.frame_present[camera][0] || !r.frame_present[camera][1]) continue;
    const std::int64_t b_minus_a = r.frame_timestamp_ns[camera][1] - r.frame_timestamp_ns[camera][0];
    EXPECT_GE(b_minus_a, 55'000'000) << "camera " << camera << " set " << k;
    EXPECT_LE(b_minus_a, 105'000'000) << "camera " << camera << " set " << k;
    offsets.push_back(r.frame_timestamp_ns[camera][0] - r.trigger_timestamp_ns);
  }
  ASSERT_FALSE(offsets.empty());
  const auto [lo, hi] = std::minmax_element(offsets.begin(), offsets.end());
  EXPECT_LT(*hi - *lo, 100'000'000) << "camera " << camera << ": a frame A belongs to another trigger event";
}

// The plan-sized buffer pools are checked against the memory available before any camera is
// opened: four 2048 x 2048 Mono16 cameras at 5 Hz hold 4 x 18 buffers of 8.4 MB (604 MB). A
// meminfo file (TOMORIG_MEMINFO, the documented test seam) says 512 MB are available: refused,
// exit 2, with the figures and the fix; no camera is touched (the device ids name no camera).
class RigBufferMemory : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "the tomorig binary is not built";
    std::string big = rig_toml("two_triggers");
    for (std::string::size_type at; (at = big.find("width = 64\nheight = 48")) != std::string::npos;)
      big.replace(at, 22, "width = 2048\nheight = 2048");
    for (std::string::size_type at; (at = big.find("\"Mono8\"")) != std::string::npos;) big.replace(at, 7, "\"Mono16\"");
    for (std::string::size_type at; (at = big.find("device_id = \"127.0.0.")) != std::string::npos;)
      big.replace(at, 22, "device_id = \"192.0.2.");  // TEST-NET-1: no camera answers there
    std::ofstream(dir_ / "big.toml") << big;
  }
  void TearDown() override { unsetenv("TOMORIG_MEMINFO"); }
  CliResult run_with_available_kb(std::uint64_t kilobytes) {
    std::ofstream(dir_ / "meminfo") << "MemTotal:       99999999 kB\nMemFree:          100000 kB\nMemAvailable:   "
                                    << kilobytes << " kB\n";
    setenv("TOMORIG_MEMINFO", (dir_ / "meminfo").c_str(), 1);
    return run_tomorig("run --config " + shell_quoted((dir_ / "big.toml").string()) + " --sets 5 --status none -o " +
                       shell_quoted((dir_ / "big.h5").string()));
  }
  TempDir dir_;
};

TEST_F(RigBufferMemory, PoolsLargerThanTheMemoryAvailableAreRefusedBeforeAnyCameraIsOpened) {
  const CliResult r = run_with_available_kb(500'000);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  for (const char* part : {"0.60 GB", "0.51 GB available", "4 cameras x 18 buffers", "8.4 MB", "rate_hz 5",
                           "set timeout 0.5 s", "Lower [trigger] rate_hz", "[cameras.roi]"})
    EXPECT_NE(r.err.find(part), std::string::npos) << part << " in: " << r.err;
  EXPECT_EQ(r.err.find("not found"), std::string::npos) << "no camera may be opened: " << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "big.h5"));
  EXPECT_FALSE(std::filesystem::exists((dir_ / "big.h5").string() + ".partial"));
}

TEST_F(RigBufferMemory, PoolsThatFitPassTheCheckAndTheRunGoesOnToOpenTheCameras) {
  const CliResult r = run_with_available_kb(8'000'000);  // 8 GB: 604 MB fit
  EXPECT_EQ(r.err.find("camera buffers need"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("camera camA"), std::string::npos) << r.err;  // the absent camera is what stops it
  EXPECT_NE(r.exit_code, 0);
}

TEST_F(GigEFakeRig, TwoTriggersASetGiveCompleteSetsWhosePairsComeFromOneEvent) {
  constexpr int kSets = 20;
  write_rig(rig_toml("two_triggers"));
  const auto out = dir_ / "fakes.h5";
  CliResult r = run_tomorig("run --config " + shell_quoted(rig_.string()) + " --sets " + std::to_string(kSets) +
                            " --status none -o " + shell_quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const storage::SessionReader session(out);
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));  // never more than asked
  EXPECT_TRUE(session.recording_complete());
  // The fake looks for a trigger only on a 40 ms grid of the wall clock, so its B - A is 80 ms
  // or, when the host's scheduling delays a trigger across a grid line, 40 or 120 ms: that pair
  // is dropped (its set flagged), never kept across events. Once each camera has learned its
  // answer latency (4 events), its triggers go out just past the grid line, with 35 ms to spare
  // (AravisCameraOptions::readout_ns): on a 2-core machine running four compilers (load 13-16)
  // 20- to 60-set runs then flagged 0-2 sets, once 6 of 20 (the fakes themselves starved),
  // where a third and more were flagged before. The bound stays at a third for such machines;
  // the frames-delivered check below is the strict one.
  EXPECT_LE(session.incomplete_sets(), kSets / 3) << r.err;
  // Every trigger is answered by a frame: a trigger the fake merged with the next one or lost
  // (it sleeps through a grid line now and then; the camera nudges it) is a frame that never
  // comes, unlike a grid crossing, whose frames come and are dropped by the pair check. On a
  // quiet machine all 40 come; a host so busy that the fake's own thread waits more than a
  // trigger spacing can still merge one.
  for (int c = 0; c < kFakes; ++c) EXPECT_GE(frames_delivered(r.err, kCameraIds[c]), 2 * kSets - 2) << r.err;
  EXPECT_NE(r.out.find(fmt_lost(session)), std::string::npos) << r.out;
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord rec = session.set_record(k);
    EXPECT_EQ(rec.trigger_index, k);
    // The trigger clock throughout: event k at k / 5 Hz after the run's start.
    EXPECT_EQ(rec.trigger_timestamp_ns - session.set_record(0).trigger_timestamp_ns,
              static_cast<std::int64_t>(k) * 200'000'000);
    EXPECT_EQ(rec.dt_ns, 80'000'000);
  }
  for (int c = 0; c < kFakes; ++c) expect_pairs_from_their_own_events(session, c);
  EXPECT_EQ(session.read_set(0).cameras[3].camera_id, "camD");
}

// frame_mode "free_run": the fakes stream at their own 25 Hz, unsynchronised. Allowed, with a
// warning on every status line; their frames fill the sets marked unsynchronised
// (frame_present 2 in the file), and no set is ever called complete; the run ends normally.
TEST_F(GigEFakeRig, FreeRunningCamerasAreWarnedAboutOnEveryLineAndNoSetIsComplete) {
  constexpr int kSets = 10;
  write_rig(rig_toml("free_run"));
  const auto out = dir_ / "free.h5";
  CliResult r = run_tomorig("run --config " + shell_quoted(rig_.string()) + " --sets " + std::to_string(kSets) +
                            " --status none -o " + shell_quoted(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int status_lines = 0;
  std::istringstream lines(r.err);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("recording: set ") == std::string::npos) continue;
    ++status_lines;
    EXPECT_NE(line.find("WARNING free-running cameras camA, camB, camC, camD"), std::string::npos) << line;
  }
  EXPECT_GE(status_lines, 2) << r.err;  // the closing line at least, and one during the run
  const storage::SessionReader session(out);
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));
  EXPECT_EQ(session.incomplete_sets(), static_cast<std::uint64_t>(kSets));
  int unsynchronised = 0;
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord rec = session.set_record(k);
    for (int c = 0; c < kFakes; ++c)
      for (int e = 0; e < 2; ++e) {
        if (!rec.frame_present[c][e]) continue;
        EXPECT_FALSE(rec.frame_synchronised[c][e]) << "set " << k << " camera " << c;
        ++unsynchronised;
      }
  }
  // The fakes stream at 25 Hz, five frames a 5 Hz set: most slots are filled.
  EXPECT_GE(unsynchronised, kSets * kFakes * 2 / 2) << r.err;
}

TEST_F(GigEFakeRig, HardwareModeOnSingleFrameCamerasIsRefusedBeforeAnythingRuns) {
  write_rig(rig_toml("hardware"));
  const auto out = dir_ / "wrong-mode.h5";
  CliResult r = run_tomorig("run --config " + shell_quoted(rig_.string()) + " --sets 5 --status none -o " +
                            shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("camera camA"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("TriggerSelector"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("two_triggers"), std::string::npos) << r.err;  // says what to use instead
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

TEST_F(GigEFakeRig, ADtShorterThanTheReadoutIsRefusedAndSaysWhy) {
  write_rig(rig_toml("two_triggers", 30000));
  const auto out = dir_ / "short-dt.h5";
  CliResult r = run_tomorig("run --config " + shell_quoted(rig_.string()) + " --sets 5 --status none -o " +
                            shell_quoted(out.string()));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("readout time 40000 us"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

// Kills camC's fake after set `kill_after` and returns when the run named it: the seconds from
// the kill to the notice.
double kill_and_time_the_notice(TomorigProcess& run, pid_t& fake, int kill_after) {
  const auto line = run.wait_for_line("recording: set " + std::to_string(kill_after) + "/");
  EXPECT_TRUE(line) << run.err();
  const auto killed = Clock::now();
  ::kill(fake, SIGKILL);
  int status = 0;
  waitpid(fake, &status, 0);
  fake = -1;
  const auto notice = run.wait_for_line("camera camC vanished");
  EXPECT_TRUE(notice) << run.err();
  return std::chrono::duration<double>(Clock::now() - killed).count();
}

TEST_F(GigEFakeRig, AKilledCameraIsNamedAndContinueFinishesTheRunWithItsFramesMissing) {
  constexpr int kSets = 25, kKillAfter = 8;
  write_rig(rig_toml("two_triggers"));
  const auto out = dir_ / "continue.h5";
  TomorigProcess run({"run", "--config", rig_.string(), "--sets", std::to_string(kSets), "--status", "none",
                      "--on-camera-loss", "continue", "-o", out.string()});
  const double seconds = kill_and_time_the_notice(run, fakes_[2], kKillAfter);
  // The loss shows at the camera's next trigger (one 200 ms period at most), then within 1 s.
  EXPECT_LT(seconds, 1.2) << run.err();
  ASSERT_EQ(run.wait(), 0) << run.err();
  EXPECT_NE(run.err().find("continuing without it"), std::string::npos) << run.err();
  EXPECT_NE(run.err().find("camC DISCONNECTED"), std::string::npos) << run.err();
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));
  int flagged = 0, others_missing = 0;
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord rec = session.set_record(k);
    for (int c : {0, 1, 3}) others_missing += !rec.frame_present[c][0] + !rec.frame_present[c][1];
    if (!rec.frame_present[2][0] || !rec.frame_present[2][1]) ++flagged;
  }
  // camC's frames are missing from the kill on; the other cameras keep being triggered and
  // answer every trigger: each delivers its 50 frames, 2 at most short of that (each camera
  // has its own trigger thread, so the dead camera's unanswered commands hold up no other
  // camera; a host too busy for the fakes may merge a trigger, see the first test). Their
  // pairs in the file may miss a few more: the pair check drops the pairs a busy host pushed
  // across the fake's 40 ms grid, before the kill as much as after it (the first test), at
  // most one frame in five.
  EXPECT_GE(flagged, kSets - kKillAfter - 2);
  for (int c : {0, 1, 3}) EXPECT_GE(frames_delivered(run.err(), kCameraIds[c]), 2 * kSets - 2) << run.err();
  EXPECT_LE(others_missing, kSets * 2 * 3 / 5) << run.err();
  for (int c : {0, 1, 3}) expect_pairs_from_their_own_events(session, c);
}

TEST_F(GigEFakeRig, AKilledCameraUnderStopEndsTheRunWithACompleteReadableFile) {
  constexpr int kSets = 40, kKillAfter = 6;
  write_rig(rig_toml("two_triggers"));
  const auto out = dir_ / "stop.h5";
  TomorigProcess run({"run", "--config", rig_.string(), "--sets", std::to_string(kSets), "--status", "none", "-o",
                      out.string()});
  kill_and_time_the_notice(run, fakes_[2], kKillAfter);
  EXPECT_EQ(run.wait(), 1) << run.err();
  EXPECT_NE(run.err().find("stopping the run (--on-camera-loss stop)"), std::string::npos) << run.err();
  ASSERT_TRUE(std::filesystem::exists(out)) << run.err();
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  EXPECT_GE(session.set_count(), static_cast<std::uint64_t>(kKillAfter));
  EXPECT_LT(session.set_count(), static_cast<std::uint64_t>(kSets));
  for (std::uint64_t k = 0; k < session.set_count(); ++k) EXPECT_EQ(session.read_set(k).cameras.size(), 4u);
}

}  // namespace
}  // namespace tomorig::testing
