#pragma once
// Test sets with known pixels, and helpers shared by the stream tests.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "tomorig/core/error.h"
#include "tomorig/core/frame_set.h"

namespace tomorig::stream::testing {

// The value every test pixel gets: depends on set, camera, exposure and position, so a
// swapped, shifted or stale frame shows up.
inline std::uint32_t pattern(std::uint64_t set, int camera, int exposure, int x, int y) {
  return static_cast<std::uint32_t>(set * 7919u + camera * 131u + exposure * 17u + x * 3u + y * 101u);
}

inline Image pattern_image(int width, int height, SampleType type, std::uint64_t set, int camera, int exposure) {
  Image im = Image::allocate(width, height, type);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::uint32_t v = pattern(set, camera, exposure, x, y);
      switch (type) {
        case SampleType::u8: im.at<std::uint8_t>(x, y) = static_cast<std::uint8_t>(v); break;
        case SampleType::u16: im.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(v); break;
        case SampleType::f32: im.at<float>(x, y) = static_cast<float>(v % 100000) * 0.25f; break;
      }
    }
  return im;
}

// True if `im` holds exactly the pattern of (set, camera, exposure).
inline bool has_pattern(const Image& im, std::uint64_t set, int camera, int exposure) {
  const Image expected = pattern_image(im.width(), im.height(), im.type(), set, camera, exposure);
  return im.same_pixels(expected);
}

inline FrameSet pattern_set(std::uint64_t index, int cameras, int width, int height, SampleType type) {
  FrameSet set;
  set.set_index = index;
  set.trigger_index = 1000 + index;
  set.trigger_timestamp_ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(index) * 40'000'000;
  set.dt_ns = 12'500;
  for (int c = 0; c < cameras; ++c) {
    CameraFrames cam;
    cam.camera_id = "cam" + std::to_string(c);
    cam.a = {pattern_image(width, height, type, index, c, 0), set.trigger_timestamp_ns + c};
    cam.b = {pattern_image(width, height, type, index, c, 1), set.trigger_timestamp_ns + set.dt_ns + c};
    set.cameras.push_back(std::move(cam));
  }
  return set;
}

// True if every row of both images holds the same bytes (a bit-level comparison, strides
// may differ).
inline bool same_bits(const Image& a, const Image& b) {
  if (a.empty() || b.empty()) return a.empty() == b.empty();
  if (a.width() != b.width() || a.height() != b.height() || a.type() != b.type()) return false;
  for (int y = 0; y < a.height(); ++y)
    if (std::memcmp(a.data() + y * a.stride_bytes(), b.data() + y * b.stride_bytes(), a.row_bytes()) != 0)
      return false;
  return true;
}

inline void expect_same_set(const FrameSet& got, const FrameSet& want) {
  EXPECT_EQ(got.set_index, want.set_index);
  EXPECT_EQ(got.trigger_index, want.trigger_index);
  EXPECT_EQ(got.trigger_timestamp_ns, want.trigger_timestamp_ns);
  EXPECT_EQ(got.dt_ns, want.dt_ns);
  ASSERT_EQ(got.cameras.size(), want.cameras.size());
  for (std::size_t c = 0; c < want.cameras.size(); ++c) {
    EXPECT_EQ(got.cameras[c].camera_id, want.cameras[c].camera_id);
    for (Exposure e : {Exposure::A, Exposure::B}) {
      EXPECT_EQ(got.cameras[c][e].timestamp_ns, want.cameras[c][e].timestamp_ns);
      EXPECT_EQ(got.cameras[c][e].present(), want.cameras[c][e].present());
      EXPECT_TRUE(same_bits(got.cameras[c][e].image, want.cameras[c][e].image))
          << "camera " << c << " exposure " << static_cast<int>(e);
    }
  }
}

// Runs `f`, expects a tomorig::Error of `kind` whose message contains every one of `parts`.
template <typename F>
void expect_error(F&& f, ErrorKind kind, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "expected an error mentioning '" << (parts.empty() ? "" : parts.front()) << "'";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

}  // namespace tomorig::stream::testing
