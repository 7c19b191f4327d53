#include "tomorig/rig/buffer_memory.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "tomorig/core/error.h"

namespace tomorig::rig {
namespace {

std::string gigabytes(double bytes) { return fmt::format("{:.2f} GB", bytes / 1e9); }

}  // namespace

std::optional<std::uint64_t> memory_available_bytes() {
  const char* override_path = std::getenv("TOMORIG_MEMINFO");
  std::ifstream meminfo(override_path != nullptr && *override_path != '\0' ? override_path : "/proc/meminfo");
  std::string line;
  while (std::getline(meminfo, line)) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    std::uint64_t kilobytes = 0;
    if (fields >> kilobytes) return kilobytes * 1024;
    return std::nullopt;
  }
  return std::nullopt;
}

void check_buffer_memory(const std::vector<CameraBufferPool>& pools, double rate_hz, double set_timeout_s,
                         std::optional<std::uint64_t> available) {
  if (!available || pools.empty()) return;
  double needed = 0.0;
  for (const auto& pool : pools) needed += static_cast<double>(pool.buffers) * static_cast<double>(pool.payload_bytes);
  const double allowed = kBufferMemoryShare * static_cast<double>(*available);
  if (needed <= allowed) return;
  std::size_t largest = 0;
  for (const auto& pool : pools) largest = std::max(largest, pool.payload_bytes);
  throw bad_input(fmt::format(
      "the camera buffers need {} of memory, but this computer has {} available (MemAvailable) and at most {:.0f}% "
      "of it may hold camera buffers: {} cameras x {} buffers of up to {:.1f} MB (each camera's pool holds 2 x "
      "rate_hz {:g} x (set timeout {:g} s + 0.5 s) + 8 frames, so a set waiting for a late frame never starves the "
      "streams). Lower [trigger] rate_hz, shrink [cameras.roi], use pixel_format = \"Mono8\", or run fewer cameras "
      "on this computer",
      gigabytes(needed), gigabytes(static_cast<double>(*available)), kBufferMemoryShare * 100.0, pools.size(),
      pools.front().buffers, static_cast<double>(largest) / 1e6, rate_hz, set_timeout_s));
}

}  // namespace tomorig::rig
