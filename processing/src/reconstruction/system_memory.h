#pragma once
// What the kernel says about memory: the process's peak resident set and the memory available
// to new allocations. Reconstruction checks its estimate against the latter before allocating,
// so a volume too large is refused with a message instead of ending in the OOM killer.
#include <cstddef>
#include <string>

namespace tomorig::recon::detail {

// VmHWM from /proc/self/status, MB; 0 if unavailable.
double peak_rss_mb();
// MemAvailable from /proc/meminfo, MB; 0 if unavailable.
double available_memory_mb();

// 80 % of MemAvailable, MB: what a reconstruction may use when no limit is given.
double usable_memory_mb();

// Throws tomorig::Error (bad_input) if `bytes` exceeds the limit (limit_mb, or
// usable_memory_mb() when limit_mb <= 0). `what` says what needs the memory, for the message.
void require_memory(double bytes, double limit_mb, const std::string& what);

}  // namespace tomorig::recon::detail
