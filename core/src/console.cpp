#include "tomorig/core/console.h"

#include <unistd.h>

#include <atomic>
#include <chrono>

#include <spdlog/pattern_formatter.h>
#include <spdlog/sinks/stdout_sinks.h>
#include <spdlog/spdlog.h>

namespace tomorig {
namespace {

std::atomic<Verbosity> g_verbosity{Verbosity::normal};

// "%*": "warning: ", "error: ", "debug: ", nothing for info, so that ordinary messages read as
// before and the others say what they are.
class LevelPrefix final : public spdlog::custom_flag_formatter {
 public:
  void format(const spdlog::details::log_msg& msg, const std::tm&, spdlog::memory_buf_t& dest) override {
    const char* prefix = "";
    switch (msg.level) {
      case spdlog::level::trace: prefix = "trace: "; break;
      case spdlog::level::debug: prefix = "debug: "; break;
      case spdlog::level::warn: prefix = "warning: "; break;
      case spdlog::level::err: prefix = "error: "; break;
      case spdlog::level::critical: prefix = "critical: "; break;
      default: break;
    }
    dest.append(prefix, prefix + std::char_traits<char>::length(prefix));
  }
  std::unique_ptr<custom_flag_formatter> clone() const override { return std::make_unique<LevelPrefix>(); }
};

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

void set_verbosity(Verbosity level) {
  g_verbosity = level;
  // Log lines go to stderr beside the progress, stdout stays for results (docs/cli.md).
  static const bool configured = [] {
    auto logger = spdlog::stderr_logger_st("tomorig");
    auto formatter = std::make_unique<spdlog::pattern_formatter>();
    formatter->add_flag<LevelPrefix>('*').set_pattern("%*%v");
    logger->set_formatter(std::move(formatter));
    spdlog::set_default_logger(logger);
    return true;
  }();
  (void)configured;
  spdlog::set_level(level == Verbosity::quiet     ? spdlog::level::warn
                    : level == Verbosity::verbose ? spdlog::level::debug
                                                  : spdlog::level::info);
}

Verbosity verbosity() { return g_verbosity; }

StatusLine::StatusLine() : StatusLine(stderr, isatty(STDERR_FILENO) == 1, steady_seconds) {}

StatusLine::StatusLine(std::FILE* out, bool terminal, std::function<double()> now_seconds)
    : out_(out), terminal_(terminal), now_(std::move(now_seconds)) {}

StatusLine::~StatusLine() { break_line(); }

bool StatusLine::due() const {
  if (verbosity() == Verbosity::quiet) return false;
  return now_() - last_ >= (terminal_ ? kRedrawSeconds : kLogIntervalSeconds);
}

void StatusLine::update(std::string_view text) {
  if (due()) print(text, false);
}

void StatusLine::finish(std::string_view text) {
  if (verbosity() != Verbosity::quiet) print(text, true);
}

void StatusLine::break_line() {
  if (!line_open_) return;
  std::fputc('\n', out_);
  std::fflush(out_);
  line_open_ = false;
}

void StatusLine::print(std::string_view text, bool final) {
  last_ = now_();
  if (terminal_) {
    // Redrawn in place; spaces wipe what a longer previous text left.
    const std::size_t pad = last_width_ > text.size() ? last_width_ - text.size() : 0;
    std::fprintf(out_, "\r%.*s%*s", static_cast<int>(text.size()), text.data(), static_cast<int>(pad), "");
    last_width_ = text.size();
    line_open_ = true;
    if (final) break_line();
  } else {
    std::fprintf(out_, "%.*s\n", static_cast<int>(text.size()), text.data());
  }
  std::fflush(out_);
}

}  // namespace tomorig
