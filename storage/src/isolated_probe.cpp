#include "isolated_probe.h"

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "tomorig/core/error.h"

namespace tomorig::storage {
namespace {

// A child that exits with this code got through the reads (or they threw).
constexpr int kReadsDone = 0;

[[noreturn]] void run_child(const std::function<void()>& reads, const ProbeLimits& limits) {
  const rlimit no_core{0, 0};
  setrlimit(RLIMIT_CORE, &no_core);  // a crash here is expected to be possible; no core file
  const rlimit cpu{static_cast<rlim_t>(limits.cpu_seconds), static_cast<rlim_t>(limits.cpu_seconds) + 1};
  setrlimit(RLIMIT_CPU, &cpu);  // past the soft limit the kernel sends SIGXCPU, which kills
  signal(SIGXCPU, SIG_DFL);
  signal(SIGALRM, SIG_DFL);
  alarm(static_cast<unsigned>(limits.wall_seconds));
  try {
    reads();
  } catch (...) {
    // Whatever the reads throw, the caller's own pass throws again with its message.
  }
  _exit(kReadsDone);  // no atexit handlers, no stdio flush: the parent's buffers are not ours
}

bool is_crash_signal(int sig) {
  switch (sig) {
    case SIGSEGV: case SIGBUS: case SIGILL: case SIGFPE: case SIGABRT: case SIGSYS: case SIGTRAP:
      return true;
    default:
      return false;
  }
}

}  // namespace

std::optional<std::string> probe_in_child(const std::function<void()>& reads, const ProbeLimits& limits) {
  const pid_t child = fork();
  if (child < 0) return std::nullopt;  // cannot isolate (no memory for a process): read in-process as before
  if (child == 0) run_child(reads, limits);
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR) return std::nullopt;
  if (WIFEXITED(status)) {
    const int code = WEXITSTATUS(status);
    if (code == kReadsDone) return std::nullopt;
    // A sanitizer reports a memory error and exits with its own code instead of a signal.
    return fmt::format("made the HDF5 library fail (the reading process exited with code {})", code);
  }
  if (!WIFSIGNALED(status)) return std::nullopt;
  const int sig = WTERMSIG(status);
  if (sig == SIGXCPU)
    return fmt::format("made the HDF5 library loop without end (stopped after {} s of CPU time)", limits.cpu_seconds);
  if (is_crash_signal(sig)) return fmt::format("crashed the HDF5 library (signal {}, {})", sig, strsignal(sig));
  return std::nullopt;  // SIGALRM (blocked, see ProbeLimits), SIGKILL (OOM killer, a user), SIGINT, ...
}

void require_safe_to_read(const std::function<void()>& reads, std::string_view kind,
                          const std::filesystem::path& path) {
  if (const auto unsafe = probe_in_child(reads))
    throw bad_input(fmt::format("{} '{}' is damaged: reading its metadata {}, so tomorig does not read it (other "
                                "HDF5 tools may crash on it too). If it is a copy, copy it again from the original",
                                kind, path.string(), *unsafe));
}

}  // namespace tomorig::storage
