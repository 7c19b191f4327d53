#pragma once
// A StatusLine that also knows the rates since its last line: `tomorig replay` ("12 sets sent
// 9.9 sets/s 41.9 MB/s ...") and `tomorig record` ("12 sets 41.9 MB/s to disk ...") show how
// fast sets and bytes went by since the line was last drawn. One bookkeeping for both, so the
// two lines measure alike.
#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

#include "tomorig/core/console.h"

namespace tomorig::rig {

class RateStatusLine {
 public:
  struct Rates {
    double sets_per_second = 0.0;
    double mb_per_second = 0.0;  // 1 MB = 1e6 bytes
  };

  // On stderr with the steady clock; `enabled` false: nothing is ever drawn.
  explicit RateStatusLine(bool enabled);
  // For tests: any stream, told whether it is a terminal, and a clock in seconds.
  RateStatusLine(std::FILE* out, bool terminal, std::function<double()> now_seconds);

  // When a line is due (or `final`, which always draws and ends the line): the rates of `sets`
  // and `bytes` (running totals) since the last line, turned into the line's text by `text`.
  template <typename MakeText>
  void update(std::uint64_t sets, std::uint64_t bytes, bool final, MakeText&& text) {
    if (!enabled_ || (!final && !line_.due())) return;
    show(text(advance(sets, bytes)), final);
  }
  // Ends a line rewritten in place, so another message starts on a fresh line.
  void break_line();

 private:
  Rates advance(std::uint64_t sets, std::uint64_t bytes);
  void show(const std::string& text, bool final);

  bool enabled_;
  StatusLine line_;
  std::function<double()> now_;
  double last_;
  std::uint64_t last_sets_ = 0, last_bytes_ = 0;
};

}  // namespace tomorig::rig
