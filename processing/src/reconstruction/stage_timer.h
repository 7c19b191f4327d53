#pragma once
// Stage timings for profiling the reconstruction without a profiler: with the environment
// variable TOMORIG_RECON_PROFILE set (to anything), every mark() prints the wall time and the
// process CPU time (all threads) since the previous mark to stderr; otherwise a mark costs one
// branch. On a loaded machine the CPU time is the steadier figure.
//
//   StageTimer timer("fmart");  ...  timer.mark("mlos");  ...  timer.mark("system");
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>

namespace tomorig::recon::detail {

inline bool profiling_enabled() {
  static const bool enabled = std::getenv("TOMORIG_RECON_PROFILE") != nullptr;
  return enabled;
}

class StageTimer {
 public:
  explicit StageTimer(const char* what) : what_(what), last_(std::chrono::steady_clock::now()), last_cpu_(cpu_ms()) {}
  void mark(const char* stage) {
    if (!profiling_enabled()) return;
    const auto now = std::chrono::steady_clock::now();
    const double cpu = cpu_ms();
    std::fprintf(stderr, "[profile] %s %-24s %8.1f ms wall %8.1f ms CPU\n", what_, stage,
                 std::chrono::duration<double, std::milli>(now - last_).count(), cpu - last_cpu_);
    last_ = now;
    last_cpu_ = cpu;
  }

 private:
  static double cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
  }

  const char* what_;
  std::chrono::steady_clock::time_point last_;
  double last_cpu_;
};

}  // namespace tomorig::recon::detail
