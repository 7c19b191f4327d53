#include "rate_status_line.h"

#include <chrono>
#include <utility>

namespace tomorig::rig {
namespace {

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

RateStatusLine::RateStatusLine(bool enabled) : enabled_(enabled), now_(steady_seconds), last_(now_()) {}

RateStatusLine::RateStatusLine(std::FILE* out, bool terminal, std::function<double()> now_seconds)
    : enabled_(true), line_(out, terminal, now_seconds), now_(std::move(now_seconds)), last_(now_()) {}

RateStatusLine::Rates RateStatusLine::advance(std::uint64_t sets, std::uint64_t bytes) {
  const double now = now_();
  const double dt = now - last_;
  Rates rates;
  if (dt > 0) {
    // Totals that went back (a new count) give no rate rather than a huge one.
    rates.sets_per_second = sets >= last_sets_ ? static_cast<double>(sets - last_sets_) / dt : 0.0;
    rates.mb_per_second = bytes >= last_bytes_ ? static_cast<double>(bytes - last_bytes_) / dt / 1e6 : 0.0;
  }
  last_ = now;
  last_sets_ = sets;
  last_bytes_ = bytes;
  return rates;
}

void RateStatusLine::show(const std::string& text, bool final) {
  if (final) line_.finish(text);
  else line_.update(text);
}

void RateStatusLine::break_line() {
  if (enabled_) line_.break_line();
}

}  // namespace tomorig::rig
