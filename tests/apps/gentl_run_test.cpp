// `tomorig run` on frame-grabber cameras through GenTL: four cameras of tomorig's mock GenTL
// producer (tests/acquisition/mock_gentl, a .cti built by the tests), backend = "gentl" in the
// rig file, double-frame burst mode (one trigger, two frames), software-triggered by the rig.
// Everything goes through the product: a rig file and `tomorig run`; the checks read the
// recorded session file.
//
// The mock tags every image with its camera, the trigger it answers (counted since
// AcquisitionStart) and its place in the burst (frame A 0, frame B 1, a corrupt frame 0xEE),
// and stamps frame B one exposure time after frame A, using the ExposureTime the rig wrote.
#include <gtest/gtest.h>

#include <stdlib.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "cli_runner.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::testing {
namespace {

constexpr int kCameras = 4;
constexpr double kExposureUs = 300.0;

struct Tag {
  bool valid = false;
  std::uint32_t camera = 0;
  std::uint32_t trigger = 0;
  int frame = -1;
};

Tag read_tag(const Image& image) {
  Tag tag;
  const auto* bytes = reinterpret_cast<const unsigned char*>(image.data());
  if (image.empty() || std::memcmp(bytes, "TMG1", 4) != 0 || bytes[15] != 0x5A) return tag;
  unsigned sum = 0;
  for (int i = 0; i < 13; ++i) sum += bytes[i];
  if (bytes[13] != (sum & 0xFF) || bytes[14] != (sum >> 8)) return tag;
  std::memcpy(&tag.camera, bytes + 4, 4);
  std::memcpy(&tag.trigger, bytes + 8, 4);
  tag.frame = bytes[12];
  tag.valid = true;
  return tag;
}

// The rig: four mock cameras; `features[c]` adds [cameras.features] lines to camera c.
std::string rig_toml(const std::string& producer, const std::vector<std::string>& features = {}) {
  std::ostringstream rig;
  rig << "name = \"four cameras on a mock GenTL grabber\"\n";
  for (int c = 0; c < kCameras; ++c) {
    rig << "\n[[cameras]]\nid = \"cam" << c << "\"\nbackend = \"gentl\"\ndevice_id = \"mockcam" << c << "\"\n"
        << "producer = \"" << producer << "\"\npixel_format = \"Mono8\"\nframe_mode = \"hardware\"\n"
        << "[cameras.roi]\nwidth = 64\nheight = 48\n"
        << "[cameras.features]\nAcquisitionBurstFrameCount = \"2\"\n";
    if (c < static_cast<int>(features.size())) rig << features[c];
  }
  rig << "\n[trigger]\nbackend = \"simulated\"\nrate_hz = 25\ndt_us = 500\n"
      << "\n[trigger.camera]\nexposure_a_us = " << kExposureUs << "\n";
  return rig.str();
}

// The per-camera counters of the run's last status line ("cam1 connected 80 frames,
// underruns 0, failed 5, ..."), as text for the camera.
std::string last_status_of(const std::string& err, const std::string& camera) {
  const auto at = err.rfind(" " + camera + " ");
  if (at == std::string::npos) return {};
  const auto end = err.find_first_of(";\n", at);
  return err.substr(at + 1, end == std::string::npos ? std::string::npos : end - at - 1);
}

std::uint64_t counter(const std::string& status, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(status, m, std::regex(name + " (\\d+)"))) return ~std::uint64_t{0};
  return std::stoull(m[1]);
}

class GenTLRig : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!tomorig_built()) GTEST_SKIP() << "the tomorig binary is not built";
    rig_ = dir_ / "rig.toml";
  }
  void write_rig(const std::string& text) { std::ofstream(rig_) << text; }
  CliResult run(int sets, const std::string& out, const std::string& extra = "") {
    return run_tomorig("run --config " + shell_quoted(rig_.string()) + " --sets " + std::to_string(sets) +
                       " --status none " + extra + " -o " + shell_quoted(out));
  }

  // Every frame recorded is a good one: its tag is intact, names its camera, frame A is the
  // burst's first frame and B its second, both from one trigger, the same trigger for every
  // camera of the set. Returns the trigger of each set (from any camera present), or -1.
  std::vector<std::int64_t> check_recorded_frames(const storage::SessionReader& session) {
    std::vector<std::int64_t> triggers;
    for (std::uint64_t k = 0; k < session.set_count(); ++k) {
      const FrameSet set = session.read_set(k);
      const storage::SetRecord rec = session.set_record(k);
      std::int64_t trigger = -1;
      for (int c = 0; c < kCameras; ++c) {
        std::int64_t camera_trigger = -1;
        for (int e = 0; e < 2; ++e) {
          if (!rec.frame_present[c][e]) continue;
          const Image& image = e == 0 ? set.cameras[c].a.image : set.cameras[c].b.image;
          const Tag tag = read_tag(image);
          EXPECT_TRUE(tag.valid) << "set " << k << " camera " << c << " frame " << e << ": corrupt image recorded";
          if (!tag.valid) continue;
          EXPECT_NE(tag.frame, 0xEE) << "set " << k << " camera " << c << ": an incomplete buffer was recorded";
          EXPECT_EQ(tag.frame, e) << "set " << k << " camera " << c << ": A and B swapped";
          EXPECT_EQ(tag.camera, static_cast<std::uint32_t>(c)) << "set " << k;
          if (camera_trigger >= 0) {
            EXPECT_EQ(camera_trigger, tag.trigger) << "set " << k << " camera " << c << ": A and B of different triggers";
          }
          camera_trigger = tag.trigger;
        }
        if (rec.frame_present[c][0] && rec.frame_present[c][1]) {
          EXPECT_EQ(rec.frame_timestamp_ns[c][1] - rec.frame_timestamp_ns[c][0],
                    static_cast<std::int64_t>(kExposureUs * 1000))
              << "set " << k << " camera " << c << ": B - A is not the exposure the rig wrote";
        }
        if (camera_trigger < 0) continue;
        if (trigger >= 0) {
          EXPECT_EQ(trigger, camera_trigger) << "set " << k << ": cameras answer different triggers";
        }
        trigger = camera_trigger;
      }
      triggers.push_back(trigger);
    }
    return triggers;
  }

  TempDir dir_;
  std::filesystem::path rig_;
};

// The acceptance run: 200 double-frame sets, zero loss, every pair from one trigger.
TEST_F(GenTLRig, FourCamerasRecord200DoubleFrameSetsWithoutLossAndCorrectPairs) {
  constexpr int kSets = 200;
  write_rig(rig_toml(TOMORIG_MOCK_GENTL));
  const auto out = (dir_ / "gentl.h5").string();
  const CliResult r = run(kSets, out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const storage::SessionReader session(out);
  EXPECT_TRUE(session.recording_complete());
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));
  EXPECT_EQ(session.missing_frames(), 0) << r.err;
  EXPECT_EQ(session.incomplete_sets(), 0) << r.err;
  EXPECT_NE(r.out.find("0 lost frames, 0 incomplete sets"), std::string::npos) << r.out;
  const auto triggers = check_recorded_frames(session);
  // Set k answers the (k + first)th trigger: consecutive, none skipped or repeated.
  ASSERT_EQ(triggers.size(), static_cast<std::size_t>(kSets));
  for (std::size_t k = 1; k < triggers.size(); ++k) EXPECT_EQ(triggers[k], triggers[0] + static_cast<std::int64_t>(k));
  EXPECT_EQ(session.read_set(0).cameras[0].a.image.width(), 64);
  for (int c = 0; c < kCameras; ++c) {
    const std::string status = last_status_of(r.err, "cam" + std::to_string(c));
    EXPECT_NE(status.find("connected"), std::string::npos) << r.err;
    EXPECT_EQ(counter(status, "failed"), 0u) << status;
    EXPECT_EQ(counter(status, "underruns"), 0u) << status;
  }
}

// An older producer (no GenTL 1.3+ functions, timestamps in ticks, aligned buffers) serving a
// zipped description of cameras without PayloadSize records the same.
TEST_F(GenTLRig, AProducerWithoutOptionalFunctionsRecords) {
  write_rig(rig_toml(TOMORIG_MOCK_GENTL_V12));
  const auto out = (dir_ / "v12.h5").string();
  setenv("MOCK_GENTL_XML", "zip", 1);
  setenv("MOCK_GENTL_NO_PAYLOADSIZE", "1", 1);
  const CliResult r = run(20, out);
  unsetenv("MOCK_GENTL_XML");
  unsetenv("MOCK_GENTL_NO_PAYLOADSIZE");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const storage::SessionReader session(out);
  EXPECT_EQ(session.missing_frames(), 0) << r.err;
  check_recorded_frames(session);
}

// Injected faults, one per camera: each is counted and flagged, the run goes on, and no
// corrupt frame is ever recorded as good.
TEST_F(GenTLRig, InjectedFaultsAreCountedFlaggedAndNeverRecordedAsGood) {
  constexpr int kSets = 60;
  write_rig(rig_toml(TOMORIG_MOCK_GENTL, {"", "MockIncompleteEvery = \"7\"\n", "MockDropEvery = \"9\"\n",
                                          "MockUnderrunEvery = \"11\"\n"}));
  const auto out = (dir_ / "faults.h5").string();
  const CliResult r = run(kSets, out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const storage::SessionReader session(out);
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));
  int missing[kCameras] = {};
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord rec = session.set_record(k);
    for (int c = 0; c < kCameras; ++c) missing[c] += !rec.frame_present[c][0] + !rec.frame_present[c][1];
  }
  EXPECT_EQ(missing[0], 0) << r.err;
  // 120 frames a camera (plus the warm-up pair): about 1 in 7, 9 and 11 of them are lost.
  EXPECT_GE(missing[1], 120 / 7 - 1) << r.err;
  EXPECT_GE(missing[2], 120 / 9 - 1) << r.err;
  EXPECT_GE(missing[3], 120 / 11 - 1) << r.err;
  EXPECT_EQ(session.missing_frames(), missing[1] + missing[2] + missing[3]);
  EXPECT_GT(session.incomplete_sets(), 0);
  check_recorded_frames(session);
  // The status counts each fault where it happened.
  EXPECT_GE(counter(last_status_of(r.err, "cam1"), "failed"), static_cast<std::uint64_t>(120 / 7 - 1)) << r.err;
  EXPECT_EQ(counter(last_status_of(r.err, "cam0"), "failed"), 0u) << r.err;
  EXPECT_GE(counter(last_status_of(r.err, "cam3"), "underruns"), static_cast<std::uint64_t>(120 / 11 - 1)) << r.err;
  EXPECT_NE(r.out.find(std::to_string(session.missing_frames()) + " lost frames"), std::string::npos) << r.out;
}

// A camera that stops answering (a timeout) is named, the run goes on without it.
TEST_F(GenTLRig, ACameraThatStopsAnsweringIsNamedAndItsFramesRecordedMissing) {
  constexpr int kSets = 40;
  write_rig(rig_toml(TOMORIG_MOCK_GENTL, {"", "", "MockStallAfter = \"12\"\n"}));
  const auto out = (dir_ / "stall.h5").string();
  const CliResult r = run(kSets, out, "--on-camera-loss continue");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("camera cam2 vanished"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cam2 DISCONNECTED"), std::string::npos) << r.err;
  const storage::SessionReader session(out);
  ASSERT_EQ(session.set_count(), static_cast<std::uint64_t>(kSets));
  int cam2_missing = 0, others_missing = 0;
  for (std::uint64_t k = 0; k < session.set_count(); ++k) {
    const storage::SetRecord rec = session.set_record(k);
    cam2_missing += !rec.frame_present[2][0] + !rec.frame_present[2][1];
    for (int c : {0, 1, 3}) others_missing += !rec.frame_present[c][0] + !rec.frame_present[c][1];
  }
  EXPECT_GE(cam2_missing, 2 * (kSets - 12)) << r.err;  // 11 sets and the warm-up answered
  EXPECT_EQ(others_missing, 0) << r.err;
  check_recorded_frames(session);
}

// A refused feature value (the mock's burst is at most 2 frames) is named before anything runs.
TEST_F(GenTLRig, ARefusedFeatureIsNamedAndNothingIsWritten) {
  write_rig(rig_toml(TOMORIG_MOCK_GENTL, {"", "MockDropEvery = \"-1\"\n"}));
  const auto out = dir_ / "refused.h5";
  const CliResult r = run(5, out.string());
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("camera cam1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("MockDropEvery"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

// Producers that cannot be used: exit 2 naming the file and, where one is missing, the function.
TEST_F(GenTLRig, UnusableProducersExitWithCode2NamingTheFileAndSymbol) {
  struct Case {
    std::string producer;
    std::string names;
  };
  const Case cases[] = {{(dir_ / "no-such-grabber.cti").string(), "does not exist"},
                        {TOMORIG_NOT_A_PRODUCER, "GCInitLib"},
                        {TOMORIG_MOCK_GENTL_NO_QUEUE, "DSQueueBuffer"}};
  for (const auto& c : cases) {
    write_rig(rig_toml(c.producer));
    const auto out = dir_ / "unusable.h5";
    const CliResult r = run(5, out.string());
    EXPECT_EQ(r.exit_code, 2) << c.producer << "\n" << r.err;
    EXPECT_NE(r.err.find(c.producer), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.names), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("camera cam0"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
}

// A producer whose GCInitLib fails: a runtime failure (exit 1) with the producer's own message.
TEST_F(GenTLRig, AFailingGCInitLibIsARuntimeFailureQuotingTheProducer) {
  write_rig(rig_toml(TOMORIG_MOCK_GENTL));
  setenv("MOCK_GENTL_FAIL_INIT", "1", 1);
  const auto out = dir_ / "noinit.h5";
  const CliResult r = run(5, out.string());
  unsetenv("MOCK_GENTL_FAIL_INIT");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("GCInitLib"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(TOMORIG_MOCK_GENTL), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("MOCK_GENTL_FAIL_INIT"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
}

}  // namespace
}  // namespace tomorig::testing
