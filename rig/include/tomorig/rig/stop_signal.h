#pragma once
// Ctrl-C for long-running commands (record, replay, run): the first SIGINT or SIGTERM becomes a
// stop request that the command's loop notices and answers by finishing cleanly (closing the
// file, draining the stream); the second one gets the default action, so an operator can
// still force-quit a program that is stuck.
#include <chrono>

namespace tomorig::rig {

class StopSignalGuard {
 public:
  // Installs the handlers; the destructor restores the previous ones. One guard at a time per
  // process (runtime_error otherwise).
  StopSignalGuard();
  ~StopSignalGuard();
  StopSignalGuard(const StopSignalGuard&) = delete;
  StopSignalGuard& operator=(const StopSignalGuard&) = delete;

  bool stop_requested() const;
  // The signal that asked to stop (SIGINT, SIGTERM), 0 if none.
  int signal_number() const;
  // "SIGINT" / "SIGTERM" for messages; "" if no signal arrived.
  const char* signal_name() const;

  // Waits up to `timeout` and returns early, with true, when a stop is requested. Use it
  // instead of sleeping (pacing, back-off) so Ctrl-C is answered at once.
  bool wait_for(std::chrono::nanoseconds timeout) const;
};

}  // namespace tomorig::rig
