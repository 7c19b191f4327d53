#include "tomorig/rig/stop_signal.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>

#include "tomorig/core/error.h"

namespace tomorig::rig {
namespace {

// Signal handlers may only touch lock-free atomics and async-signal-safe calls, so the state
// is a handful of globals: a flag, the signal, and a self-pipe whose read end a waiting loop
// polls (a condition variable cannot be notified from a handler).
std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
int g_pipe[2] = {-1, -1};
struct sigaction g_previous_int {};
struct sigaction g_previous_term {};

void reset_to_default(int sig) {
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  sigaction(sig, &dfl, nullptr);
}

extern "C" void on_stop_signal(int sig) {
  const int saved_errno = errno;
  int expected = 0;
  if (g_signal.compare_exchange_strong(expected, sig)) {
    const char byte = 1;
    [[maybe_unused]] const auto n = write(g_pipe[1], &byte, 1);
  }
  // The next SIGINT or SIGTERM terminates the process the usual way.
  reset_to_default(SIGINT);
  reset_to_default(SIGTERM);
  errno = saved_errno;
}

}  // namespace

StopSignalGuard::StopSignalGuard() {
  if (g_installed.exchange(true)) throw runtime_error("internal: a second StopSignalGuard was created");
  g_signal = 0;
  if (pipe2(g_pipe, O_CLOEXEC | O_NONBLOCK) != 0) {
    g_installed = false;
    throw runtime_error("cannot create the pipe that delivers Ctrl-C to the main loop");
  }
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  // Plain file and pipe I/O restarts after the handler; waits in ZeroMQ (poll) still return
  // EINTR, which is what lets a blocked receive notice the stop at once.
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

StopSignalGuard::~StopSignalGuard() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
  close(g_pipe[0]);
  close(g_pipe[1]);
  g_pipe[0] = g_pipe[1] = -1;
  g_installed = false;
}

bool StopSignalGuard::stop_requested() const { return g_signal.load() != 0; }

int StopSignalGuard::signal_number() const { return g_signal.load(); }

const char* StopSignalGuard::signal_name() const {
  switch (g_signal.load()) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    default: return "";
  }
}

bool StopSignalGuard::wait_for(std::chrono::nanoseconds timeout) const {
  using namespace std::chrono;
  const auto deadline = steady_clock::now() + timeout;
  while (!stop_requested()) {
    const auto left = duration_cast<milliseconds>(deadline - steady_clock::now() + microseconds(999));
    if (left.count() <= 0) return false;
    pollfd fd{g_pipe[0], POLLIN, 0};
    poll(&fd, 1, static_cast<int>(left.count()));  // EINTR or readable: the loop re-checks the flag
  }
  return true;
}

}  // namespace tomorig::rig
