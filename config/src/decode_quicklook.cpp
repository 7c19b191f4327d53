// [quicklook] and its sub-tables: optional overrides of the quick-look library's defaults.
// The checks here are the ones a file can fail on its own (types, signs, ordered ranges); the
// library's validate() has the last word when the stage builds its options.
#include <cmath>

#include <fmt/format.h>

#include "decode.h"

namespace tomorig::config::detail {
namespace {

template <typename T>
void read_optional(TableReader& r, std::string_view key, std::optional<T>& out, const Rule<T>& rule) {
  T value{};
  if (r.read(key, value, Need::optional, rule)) out = value;
}

// A [low, high] range with 0 <= low <= high and high > 0.
void read_range(TableReader& r, std::string_view key, std::optional<std::array<double, 2>>& out) {
  std::array<double, 2> v{};
  if (!r.read_numbers(key, v)) return;
  if (!(v[0] >= 0 && v[0] <= v[1] && v[1] > 0)) {
    r.issue(key, fmt::format("[{}, {}] is not a range: need [low, high] with 0 <= low <= high and high > 0", v[0], v[1]));
    return;
  }
  out = v;
}

// N whole numbers >= 1.
template <std::size_t N>
void read_counts(TableReader& r, std::string_view key, std::optional<std::array<int, N>>& out, int max) {
  std::array<double, N> v{};
  if (!r.read_numbers(key, v)) return;
  std::array<int, N> counts{};
  for (std::size_t i = 0; i < N; ++i) {
    if (!(v[i] >= 1 && v[i] <= max && v[i] == std::floor(v[i]))) {
      r.issue(key, fmt::format("{} is not allowed: each entry must be a whole number from 1 to {}", v[i], max));
      return;
    }
    counts[i] = static_cast<int>(v[i]);
  }
  out = counts;
}

}  // namespace

void decode_quicklook(TableReader& root, QuickLookConfig& q) {
  auto r = root.table("quicklook");
  if (!r) return;
  read_optional(*r, "tile_px", q.tile_px, in_closed(8, 1024));
  read_optional(*r, "detail_tiles", q.detail_tiles, in_closed(1, 65536));
  read_optional(*r, "peak_sigmas", q.peak_sigmas, greater_than(0.0));
  read_range(*r, "ppp", q.ppp);
  read_range(*r, "diameter_px", q.diameter_px);
  read_optional(*r, "source_density_max", q.source_density_max, greater_than(0.0));
  read_optional(*r, "saturated_fraction_max", q.saturated_fraction_max, in_left_open(0.0, 1.0));
  read_range(*r, "energy_balance", q.energy_balance);
  read_optional(*r, "soft_tile_fraction_max", q.soft_tile_fraction_max, in_left_open(0.0, 1.0));

  if (auto d = r->table("dt_check")) {
    read_optional(*d, "window_px", q.dt_check.window_px, in_closed(8, 512));
    read_counts(*d, "windows", q.dt_check.windows, 64);
    read_optional(*d, "min_peak_ratio", q.dt_check.min_peak_ratio, at_least(1.0));
    read_range(*d, "displacement_px", q.dt_check.displacement_px);
    read_optional(*d, "valid_fraction_min", q.dt_check.valid_fraction_min, in_left_open(0.0, 1.0));
    d->report_unknown_keys();
  }
  if (auto d = r->table("drift")) {
    read_optional(*d, "warn_px", q.drift.warn_px, greater_than(0.0));
    read_optional(*d, "window_sets", q.drift.window_sets, at_least(1));
    read_counts(*d, "subvolumes", q.drift.subvolumes, 64);
    read_optional(*d, "search_radius_px", q.drift.search_radius_px, greater_than(0.0));
    d->report_unknown_keys();
  }
  if (auto p = r->table("preview")) {
    read_optional(*p, "algorithm", q.preview.algorithm, one_of<std::string>({"mlos", "ment"}));
    read_optional(*p, "binning", q.preview.binning, in_closed(1, 8));
    read_optional(*p, "depth_factor", q.preview.depth_factor, in_closed(1.0, 10.0));
    read_optional(*p, "mlos_threshold", q.preview.mlos_threshold, Rule<double>{[](const double& v) -> std::optional<std::string> {
      if (v >= 0 && v < 1) return std::nullopt;
      return std::string("must be in [0, 1)");
    }});
    read_optional(*p, "ment_iterations", q.preview.ment_iterations, in_closed(1, 20));
    p->report_unknown_keys();
  }
  if (auto p = r->table("spray")) {
    read_optional(*p, "coverage_max", q.spray.coverage_max, in_left_open(0.0, 1.0));
    read_optional(*p, "uniformity_min", q.spray.uniformity_min, in_left_open(0.0, 1.0));
    read_optional(*p, "energy_tolerance", q.spray.energy_tolerance, Rule<double>{[](const double& v) -> std::optional<std::string> {
      if (v > 0 && v < 1) return std::nullopt;
      return std::string("must be in (0, 1): the fraction pulse energies may differ and stay green");
    }});
    read_range(*p, "bright_fraction", q.spray.bright_fraction);
    if (q.spray.bright_fraction && (*q.spray.bright_fraction)[1] > 1) {
      p->issue("bright_fraction", fmt::format("[{}, {}] reaches above full scale: the high end must be at most 1",
                                              (*q.spray.bright_fraction)[0], (*q.spray.bright_fraction)[1]));
      q.spray.bright_fraction.reset();
    }
    read_range(*p, "shadow_count", q.spray.shadow_count);
    read_optional(*p, "min_intensity_max", q.spray.min_intensity_max, in_left_open(0.0, 1.0));
    read_optional(*p, "binning", q.spray.binning, in_closed(0, 8));
    read_optional(*p, "shadow_sigmas", q.spray.shadow_sigmas, in_closed(1.0, 50.0));
    read_optional(*p, "reference_sets", q.spray.reference_sets, in_closed(1, 10000));
    p->report_unknown_keys();
  }
  r->report_unknown_keys();
}

}  // namespace tomorig::config::detail
