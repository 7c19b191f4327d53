#pragma once
// The progress line of `tomorig process`: sets done, sets/s and ETA, on a StatusLine (redrawn
// on a terminal, a plain line every few seconds into files and pipes).
#include <chrono>
#include <cstdint>
#include <string>

#include "tomorig/core/console.h"

namespace tomorig::app {

class ProgressLine {
 public:
  explicit ProgressLine(std::uint64_t total);
  // One more set finished; prints the updated line when due (always the last one).
  void set_done();
  double elapsed_seconds() const;
  double sets_per_second() const;
  std::uint64_t done() const { return done_; }
  // Before another message: ends a line being redrawn.
  void break_line() { line_.break_line(); }
  // "[#####-----] 5/20 sets  0.12 sets/s  ETA 2m05s"
  std::string text() const;

 private:
  std::uint64_t total_;
  std::uint64_t done_ = 0;
  std::chrono::steady_clock::time_point start_;
  StatusLine line_;
};

// "1h02m", "2m05s", "12s".
std::string format_duration(double seconds);

}  // namespace tomorig::app
