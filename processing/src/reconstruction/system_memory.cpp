#include "system_memory.h"

#include <fstream>
#include <sstream>

#include <fmt/core.h>

#include "tomorig/core/error.h"

namespace tomorig::recon::detail {
namespace {

// The value in kB of the line "key: value kB" of a /proc file, as MB; 0 if missing.
double proc_field_mb(const char* path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) != 0 || line.size() <= key.size() || line[key.size()] != ':') continue;
    std::istringstream fields(line.substr(key.size() + 1));
    double kb = 0;
    fields >> kb;
    return kb / 1024.0;
  }
  return 0.0;
}

// Of MemAvailable, the share one reconstruction may take: the rest is left to the page cache
// and to the other processes on the machine.
constexpr double kUsableShare = 0.8;

}  // namespace

double peak_rss_mb() { return proc_field_mb("/proc/self/status", "VmHWM"); }
double available_memory_mb() { return proc_field_mb("/proc/meminfo", "MemAvailable"); }
double usable_memory_mb() { return kUsableShare * available_memory_mb(); }

void require_memory(double bytes, double limit_mb, const std::string& what) {
  const bool from_system = !(limit_mb > 0);
  const double limit = from_system ? usable_memory_mb() : limit_mb;
  if (limit <= 0) return;  // no /proc: nothing to check against
  const double needed_mb = bytes / (1024.0 * 1024.0);
  if (needed_mb > limit)
    throw bad_input(fmt::format("reconstruction: {} needs an estimated {:.0f} MB but only {:.0f} MB {}; "
                                "use a smaller grid (fewer or larger voxels), a higher mlos_threshold, or "
                                "more memory",
                                what, needed_mb, limit,
                                from_system ? "are available (80 % of MemAvailable)" : "are allowed (memory_limit_mb)"));
}

}  // namespace tomorig::recon::detail
