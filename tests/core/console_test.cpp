// StatusLine (issue 23): redrawn in place on a terminal, plain throttled lines into files and
// pipes, nothing when quiet. A fake clock drives the throttle, so nothing sleeps.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "tomorig/core/console.h"

namespace tomorig {
namespace {

struct Captured {
  char* data = nullptr;
  std::size_t size = 0;
  std::FILE* file = open_memstream(&data, &size);
  ~Captured() {
    if (file) std::fclose(file);
    std::free(data);
  }
  std::string text() {
    std::fflush(file);
    return std::string(data, size);
  }
};

struct VerbosityGuard {
  explicit VerbosityGuard(Verbosity v) { set_verbosity(v); }
  ~VerbosityGuard() { set_verbosity(Verbosity::normal); }
};

TEST(StatusLine, IntoAPipeWritesPlainLinesAtMostOneEveryFewSeconds) {
  VerbosityGuard normal(Verbosity::normal);
  Captured out;
  double now = 0;
  {
    StatusLine line(out.file, false, [&] { return now; });
    for (int second = 0; second <= 12; ++second) {
      now = second;
      line.update("at " + std::to_string(second));
    }
    line.finish("done");
  }
  const std::string text = out.text();
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
  EXPECT_EQ(text, "at 0\nat 5\nat 10\ndone\n");
}

TEST(StatusLine, OnATerminalRedrawsInPlaceAndEndsTheLineOnce) {
  VerbosityGuard normal(Verbosity::normal);
  Captured out;
  double now = 0;
  StatusLine line(out.file, true, [&] { return now; });
  line.update("long text");
  now = 0.1;
  line.update("skipped: redrawn at most 4 times a second");
  now = 0.5;
  line.update("short");
  line.break_line();
  line.break_line();  // a second call adds nothing
  EXPECT_EQ(out.text(), "\rlong text\rshort    \n");
}

TEST(StatusLine, QuietPrintsNothing) {
  VerbosityGuard quiet(Verbosity::quiet);
  Captured out;
  {
    StatusLine line(out.file, true, [] { return 100.0; });
    EXPECT_FALSE(line.due());
    line.update("progress");
    line.finish("done");
  }
  EXPECT_EQ(out.text(), "");
}

}  // namespace
}  // namespace tomorig
