#pragma once
// Helpers shared by the storage tests: temporary folders, deterministic images and small
// sessions written through the public API.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "temp_dir.h"
#include "tomorig/core/error.h"
#include "tomorig/core/frame_set.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage::testing {

using tomorig::testing::TempDir;

// Pixels that differ between cameras, sets and exposures, and use the full sample range, so
// that a swapped or truncated frame cannot go unnoticed.
inline Image test_image(int width, int height, SampleType type, std::uint32_t seed) {
  Image image = Image::allocate(width, height, type);
  std::uint32_t state = seed * 2654435761u + 12345u;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      state = state * 1664525u + 1013904223u;
      if (type == SampleType::u8) image.at<std::uint8_t>(x, y) = static_cast<std::uint8_t>(state >> 24);
      else image.at<std::uint16_t>(x, y) = static_cast<std::uint16_t>(state >> 16);
    }
  return image;
}

inline SessionCamera test_camera(const std::string& id, int width, int height, PixelFormat format) {
  SessionCamera c;
  c.id = id;
  c.width = width;
  c.height = height;
  c.pixel_format = format;
  c.pixel_pitch_um = 7.4;
  return c;
}

// Writer options without spelling out every field (aggregate initialisation would warn about
// the ones left out).
inline SessionWriterOptions writer_options(Compression compression, bool overwrite = false) {
  SessionWriterOptions o;
  o.compression = compression;
  o.overwrite = overwrite;
  return o;
}

// A full set for `cameras`, every frame present.
inline FrameSet test_set(const std::vector<SessionCamera>& cameras, std::uint64_t index) {
  FrameSet set;
  set.set_index = index;
  set.trigger_index = 1000 + index;
  set.trigger_timestamp_ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(index) * 100'000'000;
  set.dt_ns = 100'000 + static_cast<std::int64_t>(index);
  std::uint32_t seed = static_cast<std::uint32_t>(index * 100);
  for (const auto& c : cameras) {
    CameraFrames frames;
    frames.camera_id = c.id;
    frames.a.image = test_image(c.width, c.height, sample_type_of(c.pixel_format), ++seed);
    frames.a.timestamp_ns = set.trigger_timestamp_ns + 17;
    frames.b.image = test_image(c.width, c.height, sample_type_of(c.pixel_format), ++seed);
    frames.b.timestamp_ns = set.trigger_timestamp_ns + set.dt_ns + 23;
    set.cameras.push_back(std::move(frames));
  }
  return set;
}

// Writes a finished session with `sets` full sets.
inline void write_test_session(const std::filesystem::path& path, const std::vector<SessionCamera>& cameras,
                               int sets, const SessionWriterOptions& options = {}) {
  SessionInfo info;
  info.cameras = cameras;
  info.rig_config_toml = "name = \"test rig\"\n";
  SessionWriter writer(path, info, options);
  for (int s = 0; s < sets; ++s) writer.append(test_set(cameras, static_cast<std::uint64_t>(s)));
  writer.finish();
}

// Runs `body`, which must throw tomorig::Error of `kind` whose message contains every one of
// `needles`; reports the message otherwise.
template <typename Body>
void expect_error(Body&& body, ErrorKind kind, const std::vector<std::string>& needles) {
  try {
    body();
    ADD_FAILURE() << "expected tomorig::Error, nothing was thrown";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), kind) << e.what();
    for (const auto& needle : needles)
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
          << "message lacks '" << needle << "': " << e.what();
  }
}

}  // namespace tomorig::storage::testing
