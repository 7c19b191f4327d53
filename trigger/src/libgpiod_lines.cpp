// GpioLines on libgpiod 1.6 (the C API): chips opened by name, one request per line.
#include <gpiod.h>

#include <cerrno>
#include <cstring>
#include <map>

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/trigger/gpio_device.h"

namespace tomorig::trigger {
namespace {

struct ChipCloser {
  void operator()(gpiod_chip* chip) const { gpiod_chip_close(chip); }
};

class LibgpiodLines final : public GpioLines {
 public:
  ~LibgpiodLines() override { release(); }

  void request(const std::vector<GpioLineId>& ids, const std::string& consumer) override {
    release();
    for (const auto& id : ids) {
      auto& chip = chips_[id.chip];
      if (!chip) {
        chip.reset(gpiod_chip_open_by_name(id.chip.c_str()));
        if (!chip) {
          const int err = errno;
          chips_.erase(id.chip);
          release();
          throw runtime_error(fmt::format("GPIO chip '{}' cannot be opened (/dev/{}): {}; check the chip name in "
                                          "[[trigger.channels]] against `gpiodetect`",
                                          id.chip, id.chip, std::strerror(err)));
        }
      }
      gpiod_line* line = gpiod_chip_get_line(chip.get(), id.offset);
      if (!line) {
        const int err = errno;
        release();
        throw runtime_error(fmt::format("GPIO chip '{}' has no line {}: {}; `gpioinfo {}` lists its lines", id.chip,
                                        id.offset, std::strerror(err), id.chip));
      }
      if (gpiod_line_request_output(line, consumer.c_str(), 0) < 0) {
        const int err = errno;
        release();
        throw runtime_error(fmt::format("cannot claim GPIO chip '{}' line {} as an output: {} (is another program "
                                        "holding it? see `gpioinfo {}`)",
                                        id.chip, id.offset, std::strerror(err), id.chip));
      }
      lines_.push_back({line, id});
    }
  }

  void set(std::size_t index, bool high) override {
    if (index >= lines_.size()) throw runtime_error(fmt::format("GPIO line index {} was never requested", index));
    if (gpiod_line_set_value(lines_[index].line, high ? 1 : 0) < 0)
      throw runtime_error(fmt::format("setting GPIO chip '{}' line {} failed: {}", lines_[index].id.chip,
                                      lines_[index].id.offset, std::strerror(errno)));
  }

  void release() override {
    for (auto& l : lines_) gpiod_line_release(l.line);
    lines_.clear();
    chips_.clear();
  }

 private:
  struct Claimed {
    gpiod_line* line;
    GpioLineId id;
  };
  std::map<std::string, std::unique_ptr<gpiod_chip, ChipCloser>> chips_;
  std::vector<Claimed> lines_;
};

}  // namespace

std::unique_ptr<GpioLines> make_libgpiod_lines() { return std::make_unique<LibgpiodLines>(); }

}  // namespace tomorig::trigger
