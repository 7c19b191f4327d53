#pragma once
// A scripted sender for end-to-end tests of `tomorig record`: the stream library in the test
// process, bound to a free loopback port as acquire and replay bind, and small frame sets whose
// pixels say which set and camera they belong to, so a test can check what the file holds.
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <zmq.hpp>

#include "tomorig/core/frame_set.h"
#include "tomorig/stream/frame_sender.h"
#include "tomorig/stream/session_messages.h"

namespace tomorig::testing {

inline constexpr int kSmallWidth = 16;
inline constexpr int kSmallHeight = 8;

// The value of pixel (x, y) of camera `camera` in set `index` of small_set().
inline std::uint16_t small_pixel(std::uint64_t index, int camera, int x, int y) {
  return static_cast<std::uint16_t>(index * 1000 + static_cast<std::uint64_t>(camera) * 100 + x + y);
}

// Two 16 x 8 Mono16 cameras, cam0 and cam1, both frames present.
inline FrameSet small_set(std::uint64_t index) {
  FrameSet set;
  set.set_index = index;
  set.trigger_index = 100 + index;
  set.trigger_timestamp_ns = 1'000'000'000 + static_cast<std::int64_t>(index) * 100'000'000;
  set.dt_ns = 50'000;
  for (int c = 0; c < 2; ++c) {
    CameraFrames cam;
    cam.camera_id = "cam" + std::to_string(c);
    for (Frame* f : {&cam.a, &cam.b}) {
      f->image = Image::allocate(kSmallWidth, kSmallHeight, SampleType::u16);
      for (int y = 0; y < kSmallHeight; ++y)
        for (int x = 0; x < kSmallWidth; ++x) f->image.at<std::uint16_t>(x, y) = small_pixel(index, c, x, y);
      f->timestamp_ns = set.trigger_timestamp_ns;
    }
    set.cameras.push_back(std::move(cam));
  }
  return set;
}

// A session start announcing small_set()'s cameras with a pixel pitch of 5.5 um.
inline stream::SessionStart small_start(std::uint64_t id) {
  stream::SessionStart start;
  start.session_id = id;
  start.info.rig_config_toml = "name = \"scripted\"\n";
  start.info.software_version = "scripted-sender";
  start.info.cameras = {{"cam0", kSmallWidth, kSmallHeight, PixelFormat::Mono16, 5.5},
                        {"cam1", kSmallWidth, kSmallHeight, PixelFormat::Mono16, 5.5}};
  return start;
}

class ScriptedSender {
 public:
  ScriptedSender() : sender_(context_, options()) {}
  stream::FrameSender& operator*() { return sender_; }
  stream::FrameSender* operator->() { return &sender_; }
  zmq::context_t& context() { return context_; }

 private:
  static stream::SocketOptions options() {
    stream::SocketOptions o;
    o.endpoint.address = "tcp://127.0.0.1:*";
    o.timeout = std::chrono::seconds(30);  // the first send waits for record to connect
    return o;
  }
  zmq::context_t context_;
  stream::FrameSender sender_;
};

}  // namespace tomorig::testing
