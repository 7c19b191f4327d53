#pragma once
// The progress line of `tomorig process`: sets done, sets/s and ETA, and the step in hand inside
// a set (a set can take minutes), on a StatusLine (redrawn on a terminal, a plain line every few
// seconds into files and pipes). Thread-safe: with reconstruction and correlation overlapped the
// back-end reports steps from two threads.
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

#include "tomorig/core/console.h"

namespace tomorig::app {

class ProgressLine {
 public:
  explicit ProgressLine(std::uint64_t total);
  // One more set finished; prints the updated line when due (always the last one).
  void set_done();
  // The step in hand: of the set being reconstructed (`reconstruction`) or being correlated.
  void step(const std::string& text, bool reconstruction);
  double elapsed_seconds() const;
  double sets_per_second() const;
  std::uint64_t done() const { return done_; }
  // Before another message: ends a line being redrawn.
  void break_line() {
    const std::lock_guard lock(mutex_);
    line_.break_line();
  }
  // "[#####-----] 5/20 sets  0.12 sets/s  ETA 2m05s  | set 5: reconstructing B, iteration 3/7"
  std::string text() const;

 private:
  std::uint64_t total_;
  std::uint64_t done_ = 0;
  std::chrono::steady_clock::time_point start_;
  std::string reconstruction_step_, correlation_step_;
  mutable std::mutex mutex_;
  StatusLine line_;
};

// "1h02m", "2m05s", "12s".
std::string format_duration(double seconds);

}  // namespace tomorig::app
