// The real GenICam path: Aravis GigE Vision fake cameras (GVA on 127.0.0.1, GVB on 127.0.0.2,
// GVC on 127.0.0.3, GVD on 127.0.0.4) speaking GVCP/GVSP over loopback, software-triggered,
// with images injected through the fake's fill-pattern callback. Each fake needs its own
// address; adding one needs root, so the suite adds 127.0.0.2-4 itself, removes them
// afterwards, and is skipped (with a message) when not run as root.
#include <arv.h>
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "temp_dir.h"
#include "tomorig/acquisition/aravis_camera.h"
#include "tomorig/acquisition/frame_set_assembler.h"
#include "tomorig/core/error.h"
#include "tomorig/simulators/simulated_rig.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::acquisition {
namespace {

constexpr int kWidth = 64, kHeight = 48;
constexpr int kFakes = 4;
const char* const kAddresses[kFakes] = {"127.0.0.1", "127.0.0.2", "127.0.0.3", "127.0.0.4"};
const char* const kSerials[kFakes] = {"GVA", "GVB", "GVC", "GVD"};

// The value of pixel (x, y) of the k-th frame a camera is filled with: deterministic, so the
// test knows what was injected without keeping it, and different in every frame and camera.
std::uint16_t injected_pixel(std::uint32_t salt, std::uint64_t k, int x, int y) {
  std::uint64_t h = (salt * 0x9E3779B97F4A7C15ull) ^ (k * 0xBF58476D1CE4E5B9ull) ^
                    (static_cast<std::uint64_t>(y * kWidth + x) * 0x94D049BB133111EBull);
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return static_cast<std::uint16_t>(h);
}

struct FillState {
  std::uint32_t salt = 0;
  // When set, the k-th frame is a copy of images[k] (e.g. simulator renderings) instead of
  // the hash pattern.
  const std::vector<Image>* images = nullptr;
  std::atomic<std::uint64_t> filled{0};
  std::mutex mutex;
  std::condition_variable filled_one;  // the fake consumed a trigger and made a frame
};

// Runs on the fake camera's thread. The buffer reports size 0 while being filled, so the
// size comes from width, height and pixel format.
void fill_pattern(ArvBuffer* buffer, void* data, guint32, guint32, ArvPixelFormat format) {
  auto* state = static_cast<FillState*>(data);
  const int w = arv_buffer_get_image_width(buffer), h = arv_buffer_get_image_height(buffer);
  std::size_t size = 0;
  auto* pixels = static_cast<std::uint16_t*>(const_cast<void*>(arv_buffer_get_data(buffer, &size)));
  if (pixels == nullptr || format != ARV_PIXEL_FORMAT_MONO_16) return;
  const std::uint64_t k = state->filled.load();
  const Image* image = state->images != nullptr && k < state->images->size() ? &(*state->images)[k] : nullptr;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      pixels[y * w + x] = image != nullptr && x < image->width() && y < image->height()
                              ? image->at<std::uint16_t>(x, y)
                              : injected_pixel(state->salt, k, x, y);
  std::lock_guard lock(state->mutex);
  state->filled = k + 1;
  state->filled_one.notify_all();
}

bool run(const std::string& command) { return std::system((command + " >/dev/null 2>&1").c_str()) == 0; }

// Triggers `cams` one frame at a time for `sets` double-frame sets (two triggers per set) and
// hands every set the assembler emits to `take`, in order. A camera's next trigger is sent only
// once its fake has made the previous frame (`fills[c]`, its fill callback ran): the fake keeps
// one pending software trigger, so a second one before it fired would be lost. Returns a
// failure (with a message) if a frame never came.
::testing::AssertionResult acquire_sets(std::vector<AravisCamera*> cams, std::vector<FillState*> fills,
                                        std::uint64_t sets, const std::function<void(FrameSet&&)>& take) {
  AssemblerOptions ao;
  for (auto* cam : cams) ao.camera_ids.push_back(cam->id());
  ao.timeout = std::chrono::seconds(30);  // real clock; every set here must complete
  FrameSetAssembler assembler(ao);
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<std::uint64_t> delivered(cams.size(), 0);
  for (std::size_t c = 0; c < cams.size(); ++c)
    cams[c]->start([&, c](CameraFrame&& f) {
      assembler.add_frame(c, std::move(f));
      std::lock_guard lock(mutex);
      ++delivered[c];
      arrived.notify_all();
    });
  auto stop_all = [&] {
    for (auto* cam : cams) cam->stop();
  };
  auto failure = [&](const std::string& what) {
    stop_all();
    const StreamStatistics s = cams[0]->statistics();
    return ::testing::AssertionFailure() << what << " (" << cams[0]->id() << ": completed " << s.completed
                                         << ", failures " << s.failures << ", underruns " << s.underruns << ")";
  };
  const std::uint64_t frames = 2 * sets;
  for (std::uint64_t frame = 0; frame < frames; ++frame) {
    for (auto* cam : cams) cam->software_trigger();
    for (FillState* fill : fills) {
      std::unique_lock lock(fill->mutex);
      if (!fill->filled_one.wait_for(lock, std::chrono::seconds(5), [&] { return fill->filled.load() > frame; }))
        return failure("a fake did not take trigger " + std::to_string(frame));
    }
    while (auto set = assembler.try_pop()) take(std::move(*set));
  }
  {
    std::unique_lock lock(mutex);
    const bool all = arrived.wait_for(lock, std::chrono::seconds(10), [&] {
      for (auto d : delivered)
        if (d < frames) return false;
      return true;
    });
    if (!all) {
      lock.unlock();
      return failure("not every frame arrived");
    }
  }
  stop_all();
  assembler.flush();
  while (auto set = assembler.try_pop()) take(std::move(*set));
  return ::testing::AssertionSuccess();
}

// Every pixel of every frame of `set` is the hash pattern of camera c (salt c + 1).
void expect_injected_pattern(const FrameSet& set) {
  for (std::uint32_t c = 0; c < set.cameras.size(); ++c)
    for (Exposure e : {Exposure::A, Exposure::B}) {
      const Image& image = set.cameras[c][e].image;
      ASSERT_EQ(image.width(), kWidth);
      ASSERT_EQ(image.height(), kHeight);
      const std::uint64_t k = 2 * set.trigger_index + (e == Exposure::A ? 0 : 1);
      int wrong = 0;
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) wrong += image.at<std::uint16_t>(x, y) != injected_pixel(c + 1, k, x, y);
      EXPECT_EQ(wrong, 0) << "set " << set.trigger_index << " camera " << c << " frame " << (e == Exposure::A ? 'A' : 'B');
    }
}

void expect_lossless(const AravisCamera& cam, std::uint64_t frames) {
  const auto s = cam.statistics();
  EXPECT_EQ(s.delivered, frames) << cam.id();
  EXPECT_EQ(s.completed, frames) << cam.id();
  EXPECT_EQ(s.failures, 0u) << cam.id();
  EXPECT_EQ(s.underruns, 0u) << cam.id();
  EXPECT_EQ(s.missing_packets, 0u) << cam.id();
  EXPECT_EQ(s.frame_id_gaps, 0u) << cam.id();
}

class GigEFakeCameras : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (geteuid() != 0) return;
    // ctest may run these tests in parallel processes: they would fight over the GVCP port
    // and one could remove an address another still uses. A lock file serialises them
    // (released when the process exits).
    lock_fd_ = ::open("/tmp/tomorig-gige-fake-test.lock", O_CREAT | O_RDWR, 0644);
    if (lock_fd_ >= 0) ::flock(lock_fd_, LOCK_EX);
    // Leave an address someone else configured alone; remove only what this suite added.
    for (int c = 1; c < kFakes; ++c) {
      const std::string address = kAddresses[c];
      added_address_[c] = !run("ip -4 addr show dev lo | grep -q 'inet " + address + "/'") &&
                          run("ip addr add " + address + "/8 dev lo");
    }
  }
  static void TearDownTestSuite() {
    for (int c = 1; c < kFakes; ++c) {
      if (added_address_[c]) run(std::string("ip addr del ") + kAddresses[c] + "/8 dev lo");
      added_address_[c] = false;
    }
    if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
    lock_fd_ = -1;
  }

  void SetUp() override {
    if (geteuid() != 0)
      GTEST_SKIP() << "needs root to add the loopback addresses 127.0.0.2-4 for the second to fourth GigE fake cameras";
    for (int c = 0; c < kFakes; ++c) {
      states_[c].salt = static_cast<std::uint32_t>(c + 1);
      fakes_[c] = arv_gv_fake_camera_new(kAddresses[c], kSerials[c]);
      ASSERT_TRUE(fakes_[c] != nullptr && arv_gv_fake_camera_is_running(fakes_[c]))
          << "GigE fake " << kSerials[c] << " could not listen on " << kAddresses[c];
      ArvFakeCamera* fake = arv_gv_fake_camera_get_fake_camera(fakes_[c]);
      arv_fake_camera_set_fill_pattern(fake, fill_pattern, &states_[c]);
      // The fake honours a software trigger only at this rate (25 Hz by default).
      arv_fake_camera_set_trigger_frequency(fake, 1000.0);
    }
  }
  void TearDown() override {
    for (auto*& fake : fakes_)
      if (fake != nullptr) g_object_unref(fake);
  }

  // Opened by address: opened by device id ("Aravis-Fake-GVA") through loopback discovery,
  // the fake streams to an address nobody listens on and no frame arrives.
  static config::CameraConfig gige_config(const std::string& id, const std::string& address) {
    config::CameraConfig cfg;
    cfg.id = id;
    cfg.backend = config::CameraBackend::aravis;
    cfg.device_id = address;
    cfg.pixel_format = PixelFormat::Mono16;
    cfg.roi = {0, 0, kWidth, kHeight};
    return cfg;
  }
  static AravisCameraOptions software_triggered() {
    AravisCameraOptions o;
    o.trigger_source = "Software";
    o.frame_mode = config::FrameMode::two_triggers;  // the fake takes one frame per trigger
    o.socket_buffer_bytes = 1 << 20;
    return o;
  }

  inline static bool added_address_[kFakes] = {};
  inline static int lock_fd_ = -1;
  ArvGvFakeCamera* fakes_[kFakes] = {};
  FillState states_[kFakes];
};

TEST_F(GigEFakeCameras, DoubleFrameSetsArriveCompleteAndBitIdenticalToWhatWasInjected) {
  constexpr std::uint64_t kSets = 75;  // 150 frames per camera, across the fake's 16-bit id wrap
  AravisCamera cams[2] = {AravisCamera("camA", software_triggered()), AravisCamera("camB", software_triggered())};
  cams[0].configure(gige_config("camA", kAddresses[0]));
  cams[1].configure(gige_config("camB", kAddresses[1]));
  EXPECT_EQ(cams[0].triggers_per_set(), 2);

  std::uint64_t checked = 0;
  ASSERT_TRUE(acquire_sets({&cams[0], &cams[1]}, {&states_[0], &states_[1]}, kSets, [&](FrameSet&& set) {
    ASSERT_EQ(set.trigger_index, checked);
    ASSERT_TRUE(set.complete()) << "set " << checked;
    expect_injected_pattern(set);
    ++checked;
  }));
  EXPECT_EQ(checked, kSets);
  for (auto& cam : cams) expect_lossless(cam, 2 * kSets);
}

// The acceptance test of the real GenICam path: four GigE Vision fakes with distinct serials,
// fed simulator images, software-triggered; 200 double-frame sets are recorded into a live
// session file with zero loss, and the recorded pixels are bit-identical to what was injected.
TEST_F(GigEFakeCameras, FourCamerasRecord200DoubleFrameSetsLosslesslyAndBitIdentical) {
  constexpr std::uint64_t kSets = 200;
  // What each camera is fed: the simulator's frames A and B of sets 0..199, one view each.
  sim::SimulationOptions sim_options;
  sim_options.ppp = 0.05;
  sim_options.seed = 5;
  sim_options.threads = 1;
  for (int c = 0; c < kFakes; ++c) {
    sim::SimulatedCameraSpec spec;
    spec.id = std::string("cam") + kSerials[c];
    spec.yaw_deg = -30.0 + 20.0 * c;
    spec.width = kWidth;
    spec.height = kHeight;
    sim_options.cameras.push_back(spec);
  }
  const sim::SimulatedRig simulator(sim_options);
  std::vector<std::vector<Image>> injected(kFakes);
  for (std::uint64_t k = 0; k < kSets; ++k) {
    sim::SimulatedSet set = simulator.render_set(k);
    for (int c = 0; c < kFakes; ++c) {
      injected[c].push_back(std::move(set.frames.cameras[c].a.image));
      injected[c].push_back(std::move(set.frames.cameras[c].b.image));
    }
  }
  for (int c = 0; c < kFakes; ++c) states_[c].images = &injected[c];

  std::vector<std::unique_ptr<AravisCamera>> cams;
  std::vector<AravisCamera*> views;
  storage::SessionInfo info;
  for (int c = 0; c < kFakes; ++c) {
    const std::string id = sim_options.cameras[c].id;
    cams.push_back(std::make_unique<AravisCamera>(id, software_triggered()));
    cams.back()->configure(gige_config(id, kAddresses[c]));
    views.push_back(cams.back().get());
    info.cameras.push_back({id, kWidth, kHeight, PixelFormat::Mono16, 7.4});
  }
  tomorig::testing::TempDir dir;
  const auto path = dir / "gige.h5";
  storage::SessionWriterOptions writer_options;
  writer_options.live = true;
  storage::SessionWriter writer(path, info, writer_options);
  std::uint64_t recorded = 0;
  ASSERT_TRUE(acquire_sets(views, {&states_[0], &states_[1], &states_[2], &states_[3]}, kSets, [&](FrameSet&& set) {
    ASSERT_EQ(set.trigger_index, recorded);
    ASSERT_TRUE(set.complete()) << "set " << recorded;
    writer.append(set);
    ++recorded;
  }));
  writer.finish();
  ASSERT_EQ(recorded, kSets);
  for (const auto& cam : cams) expect_lossless(*cam, 2 * kSets);

  const storage::SessionReader session(path);
  ASSERT_EQ(session.set_count(), kSets);
  EXPECT_EQ(session.missing_frames(), 0);
  EXPECT_TRUE(session.recording_complete());
  for (std::uint64_t k = 0; k < kSets; ++k) {
    const FrameSet set = session.read_set(k);
    ASSERT_EQ(set.cameras.size(), static_cast<std::size_t>(kFakes));
    for (int c = 0; c < kFakes; ++c) {
      ASSERT_EQ(set.cameras[c].camera_id, sim_options.cameras[c].id);
      EXPECT_TRUE(set.cameras[c].a.image.same_pixels(injected[c][2 * k])) << "set " << k << " camera " << c << " A";
      EXPECT_TRUE(set.cameras[c].b.image.same_pixels(injected[c][2 * k + 1])) << "set " << k << " camera " << c << " B";
    }
  }
}

TEST_F(GigEFakeCameras, UnsupportedPixelFormatAndAbsentCameraAreNamed) {
  AravisCamera cam("camA", software_triggered());
  auto cfg = gige_config("camA", "127.0.0.1");
  cfg.pixel_format = PixelFormat::Mono12;
  try {
    cam.configure(cfg);
    FAIL() << "Mono12 accepted by a camera that lacks it";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::bad_input);
    EXPECT_NE(std::string(e.what()).find("PixelFormat"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("camA"), std::string::npos) << e.what();
  }
  AravisCamera absent("camZ", software_triggered());
  cfg = gige_config("camZ", kAddresses[0]);
  cfg.device_id = "Aravis-Fake-GVZ";
  try {
    absent.configure(cfg);
    FAIL() << "an absent camera was opened";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("camZ"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Aravis-Fake-GVZ"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Aravis-Fake-GVB"), std::string::npos) << "devices found are not listed: " << msg;
  }
}

}  // namespace
}  // namespace tomorig::acquisition

namespace tomorig::acquisition {
namespace {

// The fake drops GVSP packets at random (gvsp-lost-ratio) and does not answer resend
// requests, so damaged frames fail. Each loss must be counted, the damaged frame never
// delivered, its set flagged incomplete, and every frame that is delivered must be exactly
// what was injected.
TEST_F(GigEFakeCameras, PacketLossIsCountedAndNoCorruptFrameIsAcceptedAsGood) {
  constexpr std::uint64_t kFrames = 60;
  ArvGvFakeCamera* fake = fakes_[0];
  g_object_set(fake, "gvsp-lost-ratio", 0.004, nullptr);  // ~50 packets a frame: ~18 % of frames damaged

  std::mutex mutex;
  std::condition_variable resolved;
  std::uint64_t delivered = 0, failed = 0;
  AravisCameraOptions opt = software_triggered();
  opt.frame_retention_us = 20'000;  // a damaged frame fails 20 ms after its last packet
  opt.on_failed_frame = [&](std::uint64_t) {
    std::lock_guard lock(mutex);
    ++failed;
    resolved.notify_all();
  };
  AravisCamera cam("camA", opt);
  auto cfg = gige_config("camA", "127.0.0.1");
  cfg.roi = {0, 0, 256, 128};
  cam.configure(cfg);

  AssemblerOptions ao;
  ao.camera_ids = {"camA"};
  ao.timeout = std::chrono::seconds(30);
  FrameSetAssembler assembler(ao);
  cam.start([&](CameraFrame&& f) {
    // The sets are checked only at the end: copy so the 16 pool buffers keep cycling
    // (holding them all would show up as underruns, which is what a slow consumer causes).
    f.image = f.image.clone();
    assembler.add_frame(0, std::move(f));
    std::lock_guard lock(mutex);
    ++delivered;
    resolved.notify_all();
  });
  // A frame whose leader packet is lost vanishes without a failure; the next frame's id
  // reveals it as a gap. So: trigger each frame only once the fake has made the previous one
  // (its fill callback ran), then account for every one of the kFrames as delivered,
  // failed or a gap.
  FillState& fill = states_[0];
  auto trigger_and_wait_fill = [&](std::uint64_t frame) {
    cam.software_trigger();
    std::unique_lock lock(fill.mutex);
    return fill.filled_one.wait_for(lock, std::chrono::seconds(5), [&] { return fill.filled.load() > frame; });
  };
  for (std::uint64_t frame = 0; frame < kFrames; ++frame)
    ASSERT_TRUE(trigger_and_wait_fill(frame)) << "the fake did not take trigger " << frame;
  // Closing frames, sent without loss, reveal the losses before them (a gap shows only when
  // a later frame arrives; a damaged frame fails when later packets come in). The wait's
  // time limit only decides whether to send one more closing frame.
  g_object_set(fake, "gvsp-lost-ratio", 0.0, nullptr);
  bool accounted = false;
  for (std::uint64_t extra = 0; extra < 10 && !accounted; ++extra) {
    ASSERT_TRUE(trigger_and_wait_fill(kFrames + extra)) << "the fake did not take closing trigger " << extra;
    std::unique_lock lock(mutex);
    accounted = resolved.wait_for(lock, std::chrono::seconds(1), [&] {
      return delivered + failed + cam.statistics().frame_id_gaps >= kFrames;
    });
  }
  ASSERT_TRUE(accounted) << "frames unaccounted for: delivered " << delivered << ", failed " << failed << ", gaps "
                         << cam.statistics().frame_id_gaps;
  cam.stop();
  assembler.flush();

  std::uint64_t good_frames = 0, incomplete_sets = 0;
  while (auto set = assembler.try_pop()) {
    if (set->trigger_index >= kFrames / 2) continue;  // the closing frames
    if (!set->complete()) ++incomplete_sets;
    for (Exposure e : {Exposure::A, Exposure::B}) {
      const Frame& f = set->cameras[0][e];
      if (!f.present()) continue;
      ++good_frames;
      const std::uint64_t k = 2 * set->trigger_index + (e == Exposure::A ? 0 : 1);
      int wrong = 0;
      for (int y = 0; y < 128; ++y)
        for (int x = 0; x < 256; ++x) {
          // injected_pixel indexes pixels with the 64-pixel test width; recompute for 256.
          std::uint64_t h = (1 * 0x9E3779B97F4A7C15ull) ^ (k * 0xBF58476D1CE4E5B9ull) ^
                            (static_cast<std::uint64_t>(y * kWidth + x) * 0x94D049BB133111EBull);
          h ^= h >> 29;
          h *= 0xBF58476D1CE4E5B9ull;
          h ^= h >> 32;
          wrong += f.image.at<std::uint16_t>(x, y) != static_cast<std::uint16_t>(h);
        }
      EXPECT_EQ(wrong, 0) << "corrupt frame " << k << " accepted as good";
    }
  }
  const auto s = cam.statistics();
  const std::uint64_t lost = kFrames - good_frames;
  EXPECT_GT(lost, 0u) << "no frame was damaged: the loss path was not exercised";
  EXPECT_GT(good_frames, 0u);
  // Every lost frame is visible: as a failed buffer, a frame-id gap, or (leader lost) as
  // packets Aravis ignored for want of a frame, counted as underruns.
  EXPECT_GT(s.failures + s.frame_id_gaps, 0u);
  EXPECT_GT(s.missing_packets + s.resends + s.underruns, 0u);
  EXPECT_GT(incomplete_sets, 0u);
  std::cout << "[ loss     ] " << kFrames << " frames: " << good_frames << " good, " << failed << " failed, "
            << s.frame_id_gaps << " gaps; Aravis failures " << s.failures << ", missing packets "
            << s.missing_packets << ", resends " << s.resends << ", underruns " << s.underruns << "\n";
}

}  // namespace
}  // namespace tomorig::acquisition
