#include "process_progress.h"

#include <cmath>

#include <fmt/core.h>

namespace tomorig::app {

ProgressLine::ProgressLine(std::uint64_t total) : total_(total), start_(std::chrono::steady_clock::now()) {}

double ProgressLine::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double ProgressLine::sets_per_second() const {
  const double t = elapsed_seconds();
  return t > 0 ? static_cast<double>(done_) / t : 0.0;
}

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const auto s = static_cast<long long>(std::llround(seconds));
  if (s >= 3600) return fmt::format("{}h{:02d}m", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{}m{:02d}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

std::string ProgressLine::text() const {
  constexpr int width = 20;
  const int filled = total_ == 0 ? width : static_cast<int>(width * done_ / total_);
  const double rate = sets_per_second();
  const std::string eta = rate > 0 ? format_duration(static_cast<double>(total_ - done_) / rate) : "?";
  std::string text = fmt::format("[{}{}] {}/{} sets  {:.3g} sets/s  ETA {}", std::string(filled, '#'),
                                 std::string(width - filled, '-'), done_, total_, rate, eta);
  for (const std::string* step : {&correlation_step_, &reconstruction_step_})
    if (!step->empty()) text += "  | " + *step;
  return text;
}

void ProgressLine::step(const std::string& text, bool reconstruction) {
  const std::lock_guard lock(mutex_);
  (reconstruction ? reconstruction_step_ : correlation_step_) = text;
  if (line_.due()) line_.update(this->text());
}

void ProgressLine::set_done() {
  const std::lock_guard lock(mutex_);
  ++done_;
  correlation_step_.clear();
  if (done_ >= total_) reconstruction_step_.clear();
  if (done_ >= total_) line_.finish(text());
  else if (line_.due()) line_.update(text());
}

}  // namespace tomorig::app
