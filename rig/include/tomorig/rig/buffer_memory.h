#pragma once
// Real cameras' buffer pools are sized from the plan (rig_acquisition.cpp): at 50 Hz a 2048 x
// 2048 Mono16 camera holds ~1.3 GB of buffers. Their sum is checked against the memory the
// kernel says is available before any camera is started, so a rig this computer cannot hold is
// refused with the figures instead of being killed by the OOM killer mid-run.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tomorig::rig {

struct CameraBufferPool {
  std::string camera_id;
  int buffers = 0;
  std::size_t payload_bytes = 0;  // one frame
};

// MemAvailable of /proc/meminfo in bytes; nullopt if it cannot be read. The environment
// variable TOMORIG_MEMINFO names another file in the same format (for tests).
std::optional<std::uint64_t> memory_available_bytes();

// The share of the available memory the pools may take; the rest is for the recorder's queue,
// the writer and the system.
inline constexpr double kBufferMemoryShare = 0.8;

// Throws bad_input when the pools need more than kBufferMemoryShare of `available`, naming
// the rate, the set timeout, the camera count, what is needed and available, and the fixes.
// Does nothing when `available` is unknown.
void check_buffer_memory(const std::vector<CameraBufferPool>& pools, double rate_hz, double set_timeout_s,
                         std::optional<std::uint64_t> available);

}  // namespace tomorig::rig
