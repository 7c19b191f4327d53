#pragma once
// The progress line of `tomorig process`: sets done, sets/s and ETA, rewritten in place with
// '\r' on stderr.
#include <chrono>
#include <cstdint>
#include <string>

namespace tomorig::app {

class ProgressLine {
 public:
  explicit ProgressLine(std::uint64_t total);
  // One more set finished; prints the updated line.
  void set_done();
  double elapsed_seconds() const;
  double sets_per_second() const;
  std::uint64_t done() const { return done_; }
  // The line is on screen without its newline (some sets done, not all): a message printed now
  // needs one first.
  bool mid_line() const { return done_ > 0 && done_ < total_; }
  // "[#####-----] 5/20 sets  0.12 sets/s  ETA 2m05s"
  std::string text() const;

 private:
  std::uint64_t total_;
  std::uint64_t done_ = 0;
  std::chrono::steady_clock::time_point start_;
};

// "1h02m", "2m05s", "12s".
std::string format_duration(double seconds);

}  // namespace tomorig::app
