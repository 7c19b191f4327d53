#include "session_identity.h"

#include <cstddef>
#include <cstdint>

#include <fmt/core.h>

namespace tomorig::pipeline {
namespace {

constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;

std::uint64_t fnv1a(const unsigned char* data, std::size_t size, std::uint64_t hash = kFnvOffset) {
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 1099511628211ull;
  return hash;
}

}  // namespace

std::string session_identity(const storage::SessionReader& session) {
  const std::string& toml = session.info().rig_config_toml;
  const std::uint64_t config_hash = fnv1a(reinterpret_cast<const unsigned char*>(toml.data()), toml.size());
  std::uint64_t pixel_hash = 0;
  const FrameSet first = session.read_set(0);
  for (const CameraFrames& c : first.cameras)
    if (c.a.present()) {
      const Image& image = c.a.image;
      for (int y = 0; y < image.height(); ++y)
        pixel_hash = fnv1a(reinterpret_cast<const unsigned char*>(image.data()) + y * image.stride_bytes(),
                           image.row_bytes(), pixel_hash == 0 ? kFnvOffset : pixel_hash);
      break;
    }
  std::string cameras;
  for (const storage::SessionCamera& c : session.info().cameras)
    cameras += fmt::format("{}{}:{}x{}", cameras.empty() ? "" : ",", c.id, c.width, c.height);
  return fmt::format("{};{};config {:016x};pixels {:016x}", session.info().created_utc, cameras, config_hash,
                     pixel_hash);
}

}  // namespace tomorig::pipeline
