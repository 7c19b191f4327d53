// The light sheet in a depth profile (thesis Fig. 5.9): where it is, how thick, and the ghost
// level around it.
#include <algorithm>
#include <cmath>
#include <vector>

#include "tomorig/processing/quicklook/preview_volume.h"

namespace tomorig::quicklook {
namespace {

struct Run {
  int lo = 0, hi = 0;  // slices at or above the levels, around the peak
};

// The run of slices around `peak` at or above `low_level` going down and `high_level` going
// up; a NaN slice ends it.
Run run_above(std::span<const double> rel, int peak, double low_level, double high_level) {
  Run r{peak, peak};
  while (r.lo > 0 && std::isfinite(rel[r.lo - 1]) && rel[r.lo - 1] >= low_level) --r.lo;
  const int last = static_cast<int>(rel.size()) - 1;
  while (r.hi < last && std::isfinite(rel[r.hi + 1]) && rel[r.hi + 1] >= high_level) ++r.hi;
  return r;
}

// Mean of the finite entries of rel[first, last]; NaN if none.
double mean_of(std::span<const double> rel, int first, int last) {
  double sum = 0;
  int n = 0;
  for (int k = std::max(first, 0); k <= std::min(last, static_cast<int>(rel.size()) - 1); ++k)
    if (std::isfinite(rel[k])) {
      sum += rel[k];
      ++n;
    }
  return n > 0 ? sum / n : not_measured;
}

// Median of rel[first, last] (all finite: a run holds no NaN).
double median_of(std::span<const double> rel, int first, int last) {
  std::vector<double> v(rel.begin() + first, rel.begin() + last + 1);
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

SheetProfile analyse_depth_profile(std::span<const double> mean_intensity, double z0_mm, double dz_mm,
                                   const SheetAnalysisOptions& options) {
  SheetProfile out;
  const int n = static_cast<int>(mean_intensity.size());
  for (int k = 0; k < n; ++k) out.z_mm.push_back(z0_mm + k * dz_mm);

  int peak = -1;
  for (int k = 0; k < n; ++k)
    if (std::isfinite(mean_intensity[k]) && (peak < 0 || mean_intensity[k] > mean_intensity[peak])) peak = k;
  if (peak < 0 || !(mean_intensity[peak] > 0)) {
    out.intensity.assign(mean_intensity.begin(), mean_intensity.end());
    return out;
  }
  const double max = mean_intensity[peak];
  for (int k = 0; k < n; ++k) out.intensity.push_back(mean_intensity[k] / max);
  const std::span<const double> rel(out.intensity);

  // On each side, the level half way between the ghost level there and the level inside (the
  // median of the run, so that the edges' slopes do not pull it down). Found in a few rounds
  // from half way between the lowest slice and the maximum: a flat-topped sheet settles at once.
  const int margin = static_cast<int>(std::ceil(options.noise_margin_slices));
  double lowest = 1.0;
  for (double v : rel)
    if (std::isfinite(v)) lowest = std::min(lowest, v);
  double low_level = 0.5 * (1.0 + lowest), high_level = low_level;
  Run run = run_above(rel, peak, low_level, high_level);
  for (int round = 0; round < 4; ++round) {
    const double inside = median_of(rel, run.lo, run.hi);
    const double below = mean_of(rel, 0, run.lo - 1 - margin);
    const double above = mean_of(rel, run.hi + 1 + margin, n - 1);
    if (!std::isfinite(below) && !std::isfinite(above)) break;
    // A side without slices beyond the margin borrows the other side's ghost level.
    const double g_low = std::isfinite(below) ? below : above;
    const double g_high = std::isfinite(above) ? above : below;
    low_level = g_low + 0.5 * (inside - g_low);
    high_level = g_high + 0.5 * (inside - g_high);
    run = run_above(rel, peak, low_level, high_level);
  }

  // Edges: where the profile crosses the level, between the last slice below it and the first
  // one above. A sheet running into the grid's end (or into slices no camera sees) has no edge.
  const bool low_found = run.lo > 0 && std::isfinite(rel[run.lo - 1]);
  const bool high_found = run.hi < n - 1 && std::isfinite(rel[run.hi + 1]);
  auto crossing = [&](int outside, int inside, double level) {
    const double t = (level - rel[outside]) / (rel[inside] - rel[outside]);
    return z0_mm + (outside + t * (inside - outside)) * dz_mm;
  };
  if (low_found) out.low_edge_mm = crossing(run.lo - 1, run.lo, low_level);
  if (high_found) out.high_edge_mm = crossing(run.hi + 1, run.hi, high_level);
  out.found = low_found && high_found;
  if (!out.found) return out;
  if (out.low_edge_mm > out.high_edge_mm) std::swap(out.low_edge_mm, out.high_edge_mm);  // dz < 0
  out.position_mm = 0.5 * (out.low_edge_mm + out.high_edge_mm);
  out.thickness_mm = out.high_edge_mm - out.low_edge_mm;

  const double low_ghost = mean_of(rel, 0, run.lo - 1 - margin);
  const double high_ghost = mean_of(rel, run.hi + 1 + margin, n - 1);
  const bool low_is_low_z = dz_mm > 0;
  const double low_z_level = low_is_low_z ? low_ghost : high_ghost;
  const double high_z_level = low_is_low_z ? high_ghost : low_ghost;
  out.ghost_front = options.cameras_at_low_z ? low_z_level : high_z_level;
  out.ghost_back = options.cameras_at_low_z ? high_z_level : low_z_level;

  // RSNR as quality::reconstruction_snr: mean level of the slices inside the sheet over that of
  // the slices beyond the margin outside it.
  double outside_sum = 0;
  int outside_n = 0;
  for (int k = 0; k < n; ++k)
    if (std::isfinite(rel[k]) && (k < run.lo - margin || k > run.hi + margin)) {
      outside_sum += rel[k];
      ++outside_n;
    }
  const double inside = mean_of(rel, run.lo, run.hi);
  if (outside_n > 0) out.rsnr = outside_sum > 0 ? inside / (outside_sum / outside_n) : INFINITY;

  const bool judged = options.grid_low_z_mm != 0 || options.grid_high_z_mm != 0;
  const double slack = std::abs(dz_mm);
  const bool inside_grid = out.low_edge_mm >= options.grid_low_z_mm - slack &&
                           out.high_edge_mm <= options.grid_high_z_mm + slack;
  out.flag = !judged || inside_grid ? Flag::green : Flag::amber;
  return out;
}

}  // namespace tomorig::quicklook
