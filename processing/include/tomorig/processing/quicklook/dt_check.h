#pragma once
// The Δt check (issue 16, item 2): a coarse 2-D cross-correlation of a camera's frame A against
// its frame B on a few windows spread over the frame. If the pulse separation is right, the
// particle images move a few pixels between the exposures, each window finds one clear
// correlation peak, and the typical displacement lies in the target range (default 3-12 px:
// enough for resolution, below a quarter of a 48 px window). A Δt too long shows as large
// displacements and, once particles leave the windows, as lost peaks (low valid fraction); a
// Δt too short as displacements near zero.
//
// A stage keeps one DtCheck per camera (it owns the FFT buffers; not thread-safe) and one
// DtCheckResult, and calls check(a, b, result) per set, or every few sets: the cost is a few
// FFTs of window_px^2 per window, independent of the frame size. Nothing is allocated after
// the first call with the same options.
#include <cstdint>
#include <memory>
#include <vector>

#include "tomorig/core/image.h"
#include "tomorig/processing/quicklook/targets.h"

namespace tomorig::quicklook {

struct DtCheckOptions {
  int window_px = 64;                 // edge of the square correlation windows (8 to 512)
  int windows_x = 4, windows_y = 4;   // windows spread evenly over the frame
  // A window's displacement is valid if its highest correlation peak exceeds the second
  // highest (another local maximum at least 3 px away) by this factor, and lies off the edge
  // of the correlation plane.
  double min_peak_ratio = 1.5;
  Target displacement_px{3.0, 12.0, 0.25};  // median displacement magnitude of valid windows
  Target valid_fraction{0.8, 1.0, 0.25};

  // Throws tomorig::Error (bad_input) naming the field, its value and what is allowed.
  void validate() const;
};

struct DtWindow {
  int x0 = 0, y0 = 0;           // top-left pixel of the window in the frame
  double dx = 0, dy = 0;        // displacement from A to B, px (sub-pixel)
  double correlation = 0;       // correlation coefficient at the peak
  double peak_ratio = 0;        // highest over second highest peak (capped at 100)
  bool valid = false;
};

struct DtCheckResult {
  std::vector<DtWindow> windows;  // windows_x * windows_y, row-major
  Judged valid_fraction;
  double median_peak_ratio = 0;   // over all windows
  Judged displacement_px;         // median |d| of the valid windows; NaN if none
  double median_dx = 0, median_dy = 0;  // of the valid windows, px
  // Valid windows by displacement magnitude, 1 px bins from 0 to window_px / 2.
  std::vector<std::uint32_t> displacement_histogram;
  Flag overall() const { return worst(valid_fraction.flag, displacement_px.flag); }
};

class DtCheck {
 public:
  // Throws tomorig::Error (bad_input) for invalid options.
  explicit DtCheck(const DtCheckOptions& options = {});
  ~DtCheck();
  DtCheck(DtCheck&&) noexcept;
  DtCheck& operator=(DtCheck&&) noexcept;

  const DtCheckOptions& options() const { return options_; }

  // Correlates `a` against `b` (same size and sample type, Mono8 or Mono16) into `out`.
  // Throws tomorig::Error (bad_input) for a missing, float or mismatched frame, or one
  // smaller than a window.
  void check(const Image& a, const Image& b, DtCheckResult& out);

 private:
  struct Work;
  DtCheckOptions options_;
  std::unique_ptr<Work> work_;
};

}  // namespace tomorig::quicklook
