// RateStatusLine (rig/src, shared by replay's and record's status lines): the rates it shows are
// those of the interval since the last line drawn, on a clock the test drives.
#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "rate_status_line.h"

namespace tomorig::testing {
namespace {

std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string text;
  char buffer[256];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, f)) text.append(buffer, n);
  return text;
}

TEST(RateStatusLine, ShowsTheRatesSinceTheLastLineDrawnIntoALog) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> log(std::tmpfile(), std::fclose);
  ASSERT_NE(log, nullptr);
  double now = 100.0;
  rig::RateStatusLine line(log.get(), /*terminal=*/false, [&] { return now; });
  const auto text = [](const rig::RateStatusLine::Rates& r) {
    return fmt::format("{:.1f} sets/s {:.1f} MB/s", r.sets_per_second, r.mb_per_second);
  };
  line.update(0, 0, false, text);  // the first line is due at once: nothing has moved yet
  now = 102.0;
  line.update(20, 40'000'000, false, text);  // within the log interval: not drawn, not counted
  now = 100.0 + StatusLine::kLogIntervalSeconds;
  line.update(50, 100'000'000, false, text);  // 50 sets and 100 MB in the interval since the first
  now += 2.0;
  line.update(60, 104'000'000, true, text);  // the final line always draws: 10 sets, 4 MB in 2 s
  const double interval = StatusLine::kLogIntervalSeconds;
  EXPECT_EQ(contents(log.get()), fmt::format("0.0 sets/s 0.0 MB/s\n{:.1f} sets/s {:.1f} MB/s\n5.0 sets/s 2.0 MB/s\n",
                                             50 / interval, 100 / interval));
}

}  // namespace
}  // namespace tomorig::testing
