#pragma once
// What `tomorig preview` shows of the quick-look messages it receives (docs/wire-protocol.md,
// "Quick-look messages"): a terminal view refreshed in place (or one plain line per set when
// the output is not a terminal), one JSON line per set for scripts, and PNG snapshots with the
// numbers written on them.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tomorig/stream/preview.h"

namespace tomorig::pipeline {

struct QuickLookViewOptions {
  bool tty = false;   // a terminal: redraw the whole view in place, with coloured flags
  bool json = false;  // one JSON line per set instead of the view
  std::filesystem::path png_folder;  // empty: no snapshots
  double png_interval_s = 1.0;       // at most one snapshot per interval; 0: one per set
  bool overwrite = false;            // replace snapshots already in png_folder
  std::string source;                // the endpoint, for the title line
};

class QuickLookView {
 public:
  // Creates `png_folder` if needed; throws bad_input if it cannot, or if it already holds
  // snapshots and `overwrite` is false.
  explicit QuickLookView(QuickLookViewOptions options);
  ~QuickLookView();
  QuickLookView(QuickLookView&&) noexcept;
  QuickLookView& operator=(QuickLookView&&) noexcept;

  // One received message. Returns what to print: on a terminal the whole view (with the codes
  // that redraw it), otherwise a line per set (or its JSON); empty for a message that adds no
  // line (a preview volume outside a terminal). Throws bad_input for a message that is not a
  // quick-look message of a version this program reads.
  std::string take(const stream::PreviewMessage& message);

  std::uint64_t sets() const;  // per-set messages taken
  const std::vector<std::filesystem::path>& snapshots() const;  // written so far

 private:
  struct State;
  QuickLookViewOptions options_;
  std::unique_ptr<State> state_;
};

}  // namespace tomorig::pipeline
