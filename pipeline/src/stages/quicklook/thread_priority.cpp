#include "thread_priority.h"

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

namespace tomorig::pipeline::quicklook_stage {

std::string lower_this_thread_priority(int nice) {
  // PRIO_PROCESS with a thread id addresses that one thread on Linux (setpriority(2), NOTES).
  const auto tid = static_cast<id_t>(gettid());
  errno = 0;
  const int current = getpriority(PRIO_PROCESS, tid);
  if (current == -1 && errno != 0) return fmt::format("getpriority: {}", std::strerror(errno));
  if (current >= nice) return {};
  if (setpriority(PRIO_PROCESS, tid, nice) != 0) return fmt::format("setpriority({}): {}", nice, std::strerror(errno));
  return {};
}

std::string run_this_thread_only_when_idle() {
  sched_param param{};
  param.sched_priority = 0;  // the only priority SCHED_IDLE has
  if (const int error = pthread_setschedparam(pthread_self(), SCHED_IDLE, &param); error != 0)
    return fmt::format("pthread_setschedparam(SCHED_IDLE): {}", std::strerror(error));
  return {};
}

}  // namespace tomorig::pipeline::quicklook_stage
