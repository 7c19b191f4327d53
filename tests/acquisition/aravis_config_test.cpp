// The Aravis backend against Aravis's in-process fake camera (arv_enable_interface("Fake"),
// device "Fake_1"): configuration, feature errors, an absent camera, and the buffer pool's
// leases. Needs no network and no root. The fake ignores triggers, so frames come free-running.
#include "tomorig/acquisition/aravis_camera.h"

#include <arv.h>
#include <gtest/gtest.h>

#include <condition_variable>
#include <deque>
#include <mutex>

#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

config::CameraConfig fake_config(const std::string& id = "cam0") {
  config::CameraConfig cfg;
  cfg.id = id;
  cfg.backend = config::CameraBackend::aravis;
  cfg.device_id = "Fake_1";
  cfg.pixel_format = PixelFormat::Mono16;
  cfg.roi = {8, 4, 64, 48};
  return cfg;
}

AravisCameraOptions free_running() {
  AravisCameraOptions o;
  o.frame_mode = config::FrameMode::free_run;
  o.buffer_count = 3;
  return o;
}

class AravisFakeInterface : public ::testing::Test {
 protected:
  // GigE discovery is left out: it would add a second of broadcast timeouts to every open.
  static void SetUpTestSuite() {
    arv_enable_interface("Fake");
    arv_disable_interface("GigEVision");
  }
  static void TearDownTestSuite() { arv_enable_interface("GigEVision"); }
};

std::string error_of(const std::function<void()>& f, ErrorKind kind) {
  try {
    f();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST_F(AravisFakeInterface, UnsupportedPixelFormatNamesTheCameraAndTheFeature) {
  AravisCamera cam("cam3", free_running());
  auto cfg = fake_config("cam3");
  cfg.pixel_format = PixelFormat::Mono12;  // the fake offers Mono8 and Mono16 only
  const std::string msg = error_of([&] { cam.configure(cfg); }, ErrorKind::bad_input);
  EXPECT_TRUE(contains(msg, "cam3")) << msg;
  EXPECT_TRUE(contains(msg, "PixelFormat")) << msg;
  EXPECT_TRUE(contains(msg, "Mono12")) << msg;
  EXPECT_TRUE(contains(msg, "Mono16")) << msg;  // says what the camera offers
}

TEST_F(AravisFakeInterface, UnknownFeatureAndRefusedValueNameTheFeature) {
  AravisCamera cam("cam0", free_running());
  auto cfg = fake_config();
  cfg.features["NoSuchFeature"] = "1";
  std::string msg = error_of([&] { cam.configure(cfg); }, ErrorKind::bad_input);
  EXPECT_TRUE(contains(msg, "cam0") && contains(msg, "NoSuchFeature")) << msg;

  cfg = fake_config();
  cfg.roi.width = 100000;
  msg = error_of([&] { cam.configure(cfg); }, ErrorKind::bad_input);
  EXPECT_TRUE(contains(msg, "Width")) << msg;

  AravisCameraOptions opt = free_running();
  opt.frame_mode = config::FrameMode::two_triggers;
  opt.trigger_source = "Line42";
  AravisCamera triggered("cam1", opt);
  msg = error_of([&] { triggered.configure(fake_config("cam1")); }, ErrorKind::bad_input);
  EXPECT_TRUE(contains(msg, "TriggerSource") && contains(msg, "Line42")) << msg;
}

TEST_F(AravisFakeInterface, AbsentCameraIsNamedAndTheDevicesFoundAreListed) {
  AravisCamera cam("cam9", free_running());
  auto cfg = fake_config("cam9");
  cfg.device_id = "Aravis-Fake-NOPE";
  const std::string msg = error_of([&] { cam.configure(cfg); }, ErrorKind::runtime);
  EXPECT_TRUE(contains(msg, "cam9")) << msg;
  EXPECT_TRUE(contains(msg, "Aravis-Fake-NOPE")) << msg;
  EXPECT_TRUE(contains(msg, "Fake_1")) << msg;  // the list of devices found
}

TEST_F(AravisFakeInterface, WrongBackendOrNoDeviceIdIsBadInput) {
  AravisCamera cam("cam0", free_running());
  auto cfg = fake_config();
  cfg.backend = config::CameraBackend::simulated;
  error_of([&] { cam.configure(cfg); }, ErrorKind::bad_input);
  cfg = fake_config();
  cfg.device_id.clear();
  error_of([&] { cam.configure(cfg); }, ErrorKind::bad_input);
  error_of([&] { cam.start([](CameraFrame&&) {}); }, ErrorKind::runtime);  // not configured
  AravisCameraOptions bad;
  bad.buffer_count = 1;
  error_of([&] { AravisCamera c("x", bad); }, ErrorKind::bad_input);
}

// Frames are views over the pool's buffers: a held Image keeps its buffer out of the stream
// (its pixels never change under it), a released one goes back and is filled again.
TEST_F(AravisFakeInterface, LeasedBuffersStayIntactAndReturnToThePoolWhenReleased) {
  AravisCamera cam("cam0", free_running());
  auto cfg = fake_config();
  cam.configure(cfg);

  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<CameraFrame> frames;
  cam.start([&](CameraFrame&& f) {
    std::lock_guard lock(mutex);
    frames.push_back(std::move(f));
    arrived.notify_all();
  });
  auto next = [&]() -> CameraFrame {
    std::unique_lock lock(mutex);
    const bool ok = arrived.wait_for(lock, std::chrono::seconds(10), [&] { return !frames.empty(); });
    if (!ok) throw std::runtime_error("no frame within 10 s");
    CameraFrame f = std::move(frames.front());
    frames.pop_front();
    return f;
  };

  CameraFrame held = next();
  ASSERT_EQ(held.image.width(), 64);
  ASSERT_EQ(held.image.height(), 48);
  ASSERT_EQ(held.image.type(), SampleType::u16);
  const Image copy = held.image.clone();
  // With 3 buffers and one held, 8 more frames need the other two buffers to cycle.
  std::uint64_t last_id = held.frame_id;
  for (int i = 0; i < 8; ++i) {
    CameraFrame f = next();
    EXPECT_GT(f.frame_id, last_id);
    EXPECT_EQ(f.exposure, f.frame_id % 2 == 0 ? Exposure::A : Exposure::B);
    EXPECT_EQ(f.trigger_index, f.frame_id / 2);
    last_id = f.frame_id;
  }
  EXPECT_TRUE(held.image.same_pixels(copy)) << "a leased buffer was overwritten";
  cam.stop();
  const auto stats = cam.statistics();
  EXPECT_GE(stats.delivered, 9u);
  EXPECT_EQ(stats.failures, 0u);
  held = CameraFrame{};  // the last lease dies after stop(): the buffer still goes back safely
}

}  // namespace
}  // namespace tomorig::acquisition
