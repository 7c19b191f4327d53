#pragma once
// What a command tells its user while it works, in one place for every command:
// - verbosity (--quiet, --verbose; apps/src/main.cpp registers them on every command), which
//   also sets the level of spdlog's default logger (log lines on stderr: "warning: ...");
// - StatusLine: a progress line on stderr, redrawn in place on a terminal and written as plain
//   lines, at most one every few seconds, into files and pipes (never a '\r' there).
#include <cstdio>
#include <functional>
#include <string>
#include <string_view>

namespace tomorig {

enum class Verbosity { quiet, normal, verbose };

// quiet: warnings and errors only, no progress; normal: progress and info; verbose: also debug.
void set_verbosity(Verbosity level);
Verbosity verbosity();

class StatusLine {
 public:
  // How often a plain line is written into a file or pipe; one default, here.
  static constexpr double kLogIntervalSeconds = 5.0;
  // How often the line is redrawn on a terminal.
  static constexpr double kRedrawSeconds = 0.25;

  // On stderr; a terminal if stderr is one.
  StatusLine();
  // For tests: any stream, told whether it is a terminal, and a clock in seconds.
  StatusLine(std::FILE* out, bool terminal, std::function<double()> now_seconds);
  ~StatusLine();
  StatusLine(const StatusLine&) = delete;
  StatusLine& operator=(const StatusLine&) = delete;

  // Whether update() would print now: lets a caller skip formatting the text.
  bool due() const;
  // The current state; printed only when due.
  void update(std::string_view text);
  // The last state; always printed (unless quiet), ending the line.
  void finish(std::string_view text);
  // Ends a line being redrawn, so that a message printed next starts on a line of its own.
  void break_line();

 private:
  void print(std::string_view text, bool final);

  std::FILE* out_;
  bool terminal_;
  std::function<double()> now_;
  double last_ = -1e300;
  bool line_open_ = false;
  std::size_t last_width_ = 0;
};

}  // namespace tomorig
