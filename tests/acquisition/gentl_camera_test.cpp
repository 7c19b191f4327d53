// The gentl backend against tomorig's mock GenTL producer (mock_gentl/mock_producer.cpp, built
// as .cti files by this suite): loading and its errors, the GenICam description by port URL
// (plain, zipped, file:), features over GCReadPort / GCWritePort, streaming in the double-frame
// burst mode with software and hardware-style triggers, and the injected faults.
#include <gtest/gtest.h>

#include <dlfcn.h>
#include <stdlib.h>

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "tomorig/acquisition/gentl_camera.h"
#include "tomorig/core/error.h"

namespace tomorig::acquisition {
namespace {

using namespace std::chrono_literals;

// What the mock writes into the first 16 bytes of every image.
struct Tag {
  bool valid = false;
  std::uint32_t camera = 0;
  std::uint32_t trigger = 0;  // triggers the camera took since AcquisitionStart, from 0
  int frame = -1;             // 0: frame A of the burst, 1: frame B, 0xEE: a corrupt frame
};

Tag read_tag(const Image& image) {
  Tag tag;
  const auto* bytes = reinterpret_cast<const unsigned char*>(image.data());
  if (std::memcmp(bytes, "TMG1", 4) != 0 || bytes[15] != 0x5A) return tag;
  unsigned sum = 0;
  for (int i = 0; i < 13; ++i) sum += bytes[i];
  if (bytes[13] != (sum & 0xFF) || bytes[14] != (sum >> 8)) return tag;
  std::memcpy(&tag.camera, bytes + 4, 4);
  std::memcpy(&tag.trigger, bytes + 8, 4);
  tag.frame = bytes[12];
  tag.valid = true;
  return tag;
}

config::CameraConfig gentl_config(const std::string& id, const std::string& device, const char* producer) {
  config::CameraConfig cfg;
  cfg.id = id;
  cfg.backend = config::CameraBackend::gentl;
  cfg.device_id = device;
  cfg.producer = producer;
  cfg.pixel_format = PixelFormat::Mono8;
  cfg.roi = {0, 0, 64, 48};
  return cfg;
}

AravisCameraOptions software_burst() {
  AravisCameraOptions o;
  o.trigger_source = "Software";
  o.frame_mode = config::FrameMode::hardware;  // one trigger, two frames
  o.exposure_time_us = 250.0;
  // The tests keep every frame (and so its buffer) until the end: room for all of them, so an
  // underrun is only ever an injected one.
  o.buffer_count = 32;
  return o;
}

// Collects frames from a camera's delivery thread; waits for a count without sleeping.
class Collector {
 public:
  FrameSink sink() {
    return [this](CameraFrame&& f) {
      std::lock_guard lock(mutex_);
      frames_.push_back(std::move(f));
      changed_.notify_all();
    };
  }
  bool wait_for(std::size_t count, std::chrono::milliseconds limit = 5s) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, limit, [&] { return frames_.size() >= count; });
  }
  std::vector<CameraFrame> take() {
    std::lock_guard lock(mutex_);
    return std::move(frames_);
  }

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<CameraFrame> frames_;
};

std::string error_of(const std::function<void()>& action, ErrorKind* kind = nullptr) {
  try {
    action();
  } catch (const Error& e) {
    if (kind != nullptr) *kind = e.kind();
    return e.what();
  }
  return {};
}

TEST(GenTLProducerLoading, AMissingFileIsBadInputNamingIt) {
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message =
      error_of([&] { cam->configure(gentl_config("cam0", "mockcam0", "/nonexistent/grabber.cti")); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find("/nonexistent/grabber.cti"), std::string::npos) << message;
  EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
}

TEST(GenTLProducerLoading, ALibraryWithoutGenTLFunctionsIsNotAProducer) {
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message = error_of([&] { cam->configure(gentl_config("cam0", "mockcam0", TOMORIG_NOT_A_PRODUCER)); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find(TOMORIG_NOT_A_PRODUCER), std::string::npos) << message;
  EXPECT_NE(message.find("GCInitLib"), std::string::npos) << message;
  EXPECT_NE(message.find("not a GenTL producer"), std::string::npos) << message;
}

TEST(GenTLProducerLoading, AMissingMandatoryFunctionIsNamed) {
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message = error_of([&] { cam->configure(gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL_NO_QUEUE)); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find(TOMORIG_MOCK_GENTL_NO_QUEUE), std::string::npos) << message;
  EXPECT_NE(message.find("DSQueueBuffer"), std::string::npos) << message;
}

TEST(GenTLProducerLoading, AFailingGCInitLibIsARuntimeErrorWithTheProducersText) {
  setenv("MOCK_GENTL_FAIL_INIT", "1", 1);
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message = error_of([&] { cam->configure(gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL)); }, &kind);
  unsetenv("MOCK_GENTL_FAIL_INIT");
  EXPECT_EQ(kind, ErrorKind::runtime);
  EXPECT_NE(message.find("GCInitLib"), std::string::npos) << message;
  EXPECT_NE(message.find("MOCK_GENTL_FAIL_INIT"), std::string::npos) << message;  // GCGetLastError's text
}

TEST(GenTLProducerLoading, AnUnknownDeviceListsTheDevicesFound) {
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message = error_of([&] { cam->configure(gentl_config("cam0", "nosuchcam", TOMORIG_MOCK_GENTL)); }, &kind);
  EXPECT_EQ(kind, ErrorKind::runtime);
  EXPECT_NE(message.find("nosuchcam"), std::string::npos) << message;
  EXPECT_NE(message.find("mockcam3"), std::string::npos) << message;
}

TEST(GenTLProducerLoading, GenicamGenTL64PathFindsTheProducerWhenTheRigNamesNone) {
  // A folder that does not exist, a library that is no producer (skipped), then the producer.
  setenv("GENICAM_GENTL64_PATH",
         ("/nonexistent-dir:" + std::string(TOMORIG_NOT_A_PRODUCER) + ":" + TOMORIG_MOCK_GENTL).c_str(), 1);
  auto cam = make_gentl_camera("cam0", software_burst());
  auto cfg = gentl_config("cam0", "MOCK0002", "");  // by serial number
  EXPECT_NO_THROW(cam->configure(cfg));
  unsetenv("GENICAM_GENTL64_PATH");
  ErrorKind kind{};
  auto other = make_gentl_camera("cam1", software_burst());
  const std::string message = error_of([&] { other->configure(gentl_config("cam1", "mockcam1", "")); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find("GENICAM_GENTL64_PATH"), std::string::npos) << message;
}

TEST(GenTLProducerLoading, AnUnknownDeviceOnTheSearchPathNamesTheProducersSkipped) {
  setenv("GENICAM_GENTL64_PATH", (std::string(TOMORIG_MOCK_GENTL_NO_QUEUE) + ":" + TOMORIG_MOCK_GENTL).c_str(), 1);
  auto cam = make_gentl_camera("cam0", software_burst());
  ErrorKind kind{};
  const std::string message = error_of([&] { cam->configure(gentl_config("cam0", "nosuchcam", "")); }, &kind);
  unsetenv("GENICAM_GENTL64_PATH");
  EXPECT_EQ(kind, ErrorKind::runtime);
  EXPECT_NE(message.find("mockcam0"), std::string::npos) << message;
  EXPECT_NE(message.find("DSQueueBuffer"), std::string::npos) << message;
}

// Frames of a software-triggered burst camera: every trigger gives frames A and B, tagged with
// the same trigger, in order.
void expect_burst_pairs(const std::vector<CameraFrame>& frames, std::uint32_t camera) {
  ASSERT_EQ(frames.size() % 2, 0u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const Tag tag = read_tag(frames[i].image);
    ASSERT_TRUE(tag.valid) << "frame " << i;
    EXPECT_EQ(tag.camera, camera);
    EXPECT_EQ(tag.trigger, i / 2) << "frame " << i;
    EXPECT_EQ(tag.frame, static_cast<int>(i % 2)) << "frame " << i;
    EXPECT_EQ(frames[i].trigger_index, i / 2);
    EXPECT_EQ(frames[i].exposure, i % 2 == 0 ? Exposure::A : Exposure::B);
    EXPECT_EQ(frames[i].image.width(), 64);
    EXPECT_EQ(frames[i].image.height(), 48);
  }
}

class GenTLDescriptionSource : public ::testing::TestWithParam<const char*> {};

// The description served as local: plain (NUL padded), local: zipped, and file:.
TEST_P(GenTLDescriptionSource, FeaturesAndBurstFramesWork) {
  setenv("MOCK_GENTL_XML", GetParam(), 1);
  {
    auto cam = make_gentl_camera("cam1", software_burst());
    auto cfg = gentl_config("cam1", "mockcam1", TOMORIG_MOCK_GENTL);
    cfg.features["AcquisitionBurstFrameCount"] = "2";  // written and read back like any feature
    ASSERT_NO_THROW(cam->configure(cfg));
    Collector frames;
    cam->start(frames.sink());
    for (int t = 0; t < 5; ++t) cam->software_trigger();
    ASSERT_TRUE(frames.wait_for(10));
    cam->stop();
    expect_burst_pairs(frames.take(), 1);
    const auto stats = cam->statistics();
    EXPECT_EQ(stats.delivered, 10u);
    EXPECT_EQ(stats.completed, 10u);
    EXPECT_EQ(stats.failures, 0u);
    EXPECT_EQ(stats.underruns, 0u);
    EXPECT_EQ(stats.frame_id_gaps, 0u);
  }
  unsetenv("MOCK_GENTL_XML");
}

INSTANTIATE_TEST_SUITE_P(Urls, GenTLDescriptionSource, ::testing::Values("local", "zip", "file"));

TEST(GenTLCamera, RefusedFeatureValuesNameTheFeature) {
  auto cam = make_gentl_camera("cam0", software_burst());
  auto cfg = gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL);
  cfg.roi.width = 5000;  // the mock's sensor is at most 2048 wide
  ErrorKind kind{};
  std::string message = error_of([&] { cam->configure(cfg); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find("Width"), std::string::npos) << message;
  cfg = gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL);
  cfg.features["NoSuchFeature"] = "1";
  message = error_of([&] { cam->configure(cfg); }, &kind);
  EXPECT_EQ(kind, ErrorKind::bad_input);
  EXPECT_NE(message.find("NoSuchFeature"), std::string::npos) << message;
}

TEST(GenTLCamera, PayloadComesFromTheStreamWhenTheCameraHasNoPayloadSize) {
  setenv("MOCK_GENTL_NO_PAYLOADSIZE", "1", 1);
  {
    auto cam = make_gentl_camera("cam2", software_burst());
    auto cfg = gentl_config("cam2", "mockcam2", TOMORIG_MOCK_GENTL);
    cfg.pixel_format = PixelFormat::Mono16;
    ASSERT_NO_THROW(cam->configure(cfg));
    Collector frames;
    cam->start(frames.sink());
    for (int t = 0; t < 3; ++t) cam->software_trigger();
    ASSERT_TRUE(frames.wait_for(6));
    cam->stop();
    const auto got = frames.take();
    expect_burst_pairs(got, 2);
    EXPECT_EQ(got[0].image.type(), SampleType::u16);
  }
  unsetenv("MOCK_GENTL_NO_PAYLOADSIZE");
}

// An older producer: without GenTL 1.3+ functions, stamping in ticks, wanting aligned buffers.
TEST(GenTLCamera, AProducerWithoutOptionalFunctionsStreams) {
  auto cam = make_gentl_camera("cam0", software_burst());
  ASSERT_NO_THROW(cam->configure(gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL_V12)));
  Collector frames;
  cam->start(frames.sink());
  for (int t = 0; t < 4; ++t) cam->software_trigger();
  ASSERT_TRUE(frames.wait_for(8));
  cam->stop();
  const auto got = frames.take();
  expect_burst_pairs(got, 0);
  // This producer stamps in microsecond ticks (TIMESTAMP, TIMESTAMP_FREQUENCY = 1 MHz): frame B
  // follows A by the 250 us exposure, converted to nanoseconds.
  for (std::size_t i = 0; i + 1 < got.size(); i += 2) EXPECT_EQ(got[i + 1].timestamp_ns - got[i].timestamp_ns, 250'000);
}

// Hardware-style triggers: TriggerSource = Line1, pulses from the grabber's I/O line (the
// mock's MockGenTLFireLine); the camera is told to expect each (note_hardware_trigger).
TEST(GenTLCamera, HardwareLineTriggersGiveBurstPairs) {
  AravisCameraOptions o = software_burst();
  o.trigger_source = "Line1";
  auto cam = make_gentl_camera("cam3", o);
  ASSERT_NO_THROW(cam->configure(gentl_config("cam3", "mockcam3", TOMORIG_MOCK_GENTL)));
  void* library = dlopen(TOMORIG_MOCK_GENTL, RTLD_NOW | RTLD_NOLOAD);
  ASSERT_NE(library, nullptr);
  auto fire = reinterpret_cast<int (*)(const char*)>(dlsym(library, "MockGenTLFireLine"));
  ASSERT_NE(fire, nullptr);
  Collector frames;
  cam->start(frames.sink());
  cam->software_trigger();  // ignored by a Line1 trigger: no frame may come of it
  for (int t = 0; t < 6; ++t) {
    cam->note_hardware_trigger();
    ASSERT_EQ(fire("mockcam3"), 0);
  }
  ASSERT_TRUE(frames.wait_for(12));
  cam->stop();
  const auto got = frames.take();
  EXPECT_EQ(got.size(), 12u);
  expect_burst_pairs(got, 3);
  EXPECT_TRUE(cam->connected());
  dlclose(library);
}

// Every third frame arrives incomplete: it is counted as a failure, never delivered, and the
// frames around it keep their A/B roles.
TEST(GenTLCamera, IncompleteBuffersAreCountedAndNeverDelivered) {
  AravisCameraOptions o = software_burst();
  std::vector<std::uint64_t> failed;
  std::mutex failed_mutex;
  o.on_failed_frame = [&](std::uint64_t id) {
    std::lock_guard lock(failed_mutex);
    failed.push_back(id);
  };
  auto cam = make_gentl_camera("cam0", o);
  auto cfg = gentl_config("cam0", "mockcam0", TOMORIG_MOCK_GENTL);
  cfg.features["MockIncompleteEvery"] = "3";
  ASSERT_NO_THROW(cam->configure(cfg));
  Collector frames;
  cam->start(frames.sink());
  for (int t = 0; t < 9; ++t) cam->software_trigger();  // 18 frames: 6 incomplete (ids 2, 5, ... 17)
  ASSERT_TRUE(frames.wait_for(12));
  // Frame 17, the last, is an incomplete one: wait until the camera has seen it too.
  const auto give_up = std::chrono::steady_clock::now() + 5s;
  while (cam->statistics().failures < 6 && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(1ms);
  cam->stop();
  const auto got = frames.take();
  EXPECT_EQ(got.size(), 12u);
  for (const auto& f : got) {
    const Tag tag = read_tag(f.image);
    ASSERT_TRUE(tag.valid);
    EXPECT_NE(tag.frame, 0xEE) << "a corrupt frame was delivered";
    EXPECT_EQ(tag.trigger, f.trigger_index);
    EXPECT_EQ(tag.frame, f.exposure == Exposure::A ? 0 : 1);
  }
  const auto stats = cam->statistics();
  EXPECT_EQ(stats.failures, 6u);
  EXPECT_EQ(stats.delivered, 12u);
  std::lock_guard lock(failed_mutex);
  EXPECT_EQ(failed, (std::vector<std::uint64_t>{2, 5, 8, 11, 14, 17}));
}

// Dropped frames leave frame-id gaps; underruns are counted by the stream.
TEST(GenTLCamera, DropsAndUnderrunsAreCounted) {
  auto cam = make_gentl_camera("cam1", software_burst());
  auto cfg = gentl_config("cam1", "mockcam1", TOMORIG_MOCK_GENTL);
  cfg.features["MockDropEvery"] = "4";
  cfg.features["MockUnderrunEvery"] = "5";
  ASSERT_NO_THROW(cam->configure(cfg));
  Collector frames;
  cam->start(frames.sink());
  for (int t = 0; t < 10; ++t) cam->software_trigger();  // frames 1..20: drop 4,8,..20 (5), underrun 5,10,15 (3)
  ASSERT_TRUE(frames.wait_for(12));
  cam->stop();
  const auto got = frames.take();
  EXPECT_EQ(got.size(), 12u);
  for (const auto& f : got) {
    const Tag tag = read_tag(f.image);
    ASSERT_TRUE(tag.valid);
    EXPECT_EQ(tag.trigger, f.trigger_index);
    EXPECT_EQ(tag.frame, f.exposure == Exposure::A ? 0 : 1);
  }
  const auto stats = cam->statistics();
  EXPECT_EQ(stats.underruns, 3u);
  EXPECT_GE(stats.frame_id_gaps, 4u);  // the last drop (frame 20) leaves no gap behind it
}

// Stopped and started again (images of the first run still held): the second run streams on
// the same GenTL data stream, and the first run's images stay intact.
TEST(GenTLCamera, ARestartStreamsAgainWhileOldImagesAreHeld) {
  auto cam = make_gentl_camera("cam1", software_burst());
  ASSERT_NO_THROW(cam->configure(gentl_config("cam1", "mockcam1", TOMORIG_MOCK_GENTL)));
  Collector first;
  cam->start(first.sink());
  for (int t = 0; t < 2; ++t) cam->software_trigger();
  ASSERT_TRUE(first.wait_for(4));
  cam->stop();
  const auto kept = first.take();
  Collector second;
  cam->start(second.sink());
  for (int t = 0; t < 3; ++t) cam->software_trigger();
  ASSERT_TRUE(second.wait_for(6));
  cam->stop();
  expect_burst_pairs(kept, 1);
  expect_burst_pairs(second.take(), 1);  // AcquisitionStart restarts the mock's trigger count
}

// A camera that stops answering triggers is noticed (frame timeout) and marked disconnected.
TEST(GenTLCamera, ACameraThatStopsAnsweringIsMarkedDisconnected) {
  AravisCameraOptions o = software_burst();
  o.frame_timeout = 200ms;
  auto cam = make_gentl_camera("cam2", o);
  auto cfg = gentl_config("cam2", "mockcam2", TOMORIG_MOCK_GENTL);
  cfg.features["MockStallAfter"] = "2";
  ASSERT_NO_THROW(cam->configure(cfg));
  Collector frames;
  cam->start(frames.sink());
  for (int t = 0; t < 3; ++t) cam->software_trigger();
  ASSERT_TRUE(frames.wait_for(4));
  const auto give_up = std::chrono::steady_clock::now() + 3s;
  while (cam->connected() && std::chrono::steady_clock::now() < give_up) std::this_thread::sleep_for(10ms);
  EXPECT_FALSE(cam->connected());
  EXPECT_NE(cam->connection_problem().find("no frame"), std::string::npos) << cam->connection_problem();
  cam->stop();
  EXPECT_EQ(frames.take().size(), 4u);
}

}  // namespace
}  // namespace tomorig::acquisition
