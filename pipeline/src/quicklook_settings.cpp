#include "tomorig/pipeline/quicklook_settings.h"

#include <fmt/format.h>

#include "tomorig/core/error.h"
#include "tomorig/stream/preview.h"

namespace tomorig::pipeline {
namespace {

// A rig range onto a target's green range; the amber band stays the library's.
void apply(const std::optional<std::array<double, 2>>& range, quicklook::Target& target) {
  if (!range) return;
  target.low = (*range)[0];
  target.high = (*range)[1];
}
void apply_max(const std::optional<double>& high, quicklook::Target& target) {
  if (high) target.high = *high;
}
void apply_min(const std::optional<double>& low, quicklook::Target& target) {
  if (low) target.low = *low;
}
template <typename T, typename U>
void apply(const std::optional<T>& value, U& field) {
  if (value) field = *value;
}

// Re-throws a library validation error with the rig table it came from.
template <typename Options>
void validate(const Options& options, const char* table) {
  try {
    options.validate();
  } catch (const Error& e) {
    throw bad_input(fmt::format("rig file [{}]: {}", table, e.what()));
  }
}

}  // namespace

QuickLookSettings quicklook_settings(const config::RigConfig* rig) {
  QuickLookSettings s;
  if (rig == nullptr) return s;
  const config::QuickLookConfig& q = rig->quicklook;
  quicklook::QuickLookOptions& st = s.statistics;
  apply(q.tile_px, st.tile_px);
  apply(q.detail_tiles, st.detail_tiles);
  apply(q.peak_sigmas, st.peak_sigmas);
  apply(q.ppp, st.targets.ppp);
  apply(q.diameter_px, st.targets.diameter_px);
  apply_max(q.source_density_max, st.targets.source_density);
  apply_max(q.saturated_fraction_max, st.targets.saturated_fraction);
  apply(q.energy_balance, st.targets.energy_balance);
  apply_max(q.soft_tile_fraction_max, st.targets.soft_tile_fraction);
  validate(st, "quicklook");

  quicklook::DtCheckOptions& dt = s.dt_check;
  apply(q.dt_check.window_px, dt.window_px);
  if (q.dt_check.windows) {
    dt.windows_x = (*q.dt_check.windows)[0];
    dt.windows_y = (*q.dt_check.windows)[1];
  }
  apply(q.dt_check.min_peak_ratio, dt.min_peak_ratio);
  apply(q.dt_check.displacement_px, dt.displacement_px);
  apply_min(q.dt_check.valid_fraction_min, dt.valid_fraction);
  validate(dt, "quicklook.dt_check");

  quicklook::DriftOptions& drift = s.drift;
  apply(q.drift.warn_px, drift.warn_px);
  apply(q.drift.window_sets, drift.window_sets);
  if (q.drift.subvolumes) {
    drift.subvolumes_x = (*q.drift.subvolumes)[0];
    drift.subvolumes_y = (*q.drift.subvolumes)[1];
    drift.subvolumes_z = (*q.drift.subvolumes)[2];
  }
  apply(q.drift.search_radius_px, drift.search_radius_px);
  validate(drift, "quicklook.drift");

  quicklook::PreviewVolumeOptions& p = s.preview;
  apply(q.preview.algorithm, p.algorithm);
  apply(q.preview.binning, p.binning);
  apply(q.preview.depth_factor, p.depth_factor);
  apply(q.preview.mlos_threshold, p.mlos_threshold);
  apply(q.preview.ment_iterations, p.ment_iterations);
  validate(p, "quicklook.preview");

  quicklook::ShadowLookOptions& sh = s.shadow;
  quicklook::ShadowTargets& sp = sh.targets;
  apply_max(q.spray.coverage_max, sp.shadow_coverage);
  apply_min(q.spray.uniformity_min, sp.uniformity);
  if (q.spray.energy_tolerance) {
    sp.energy_ratio.low = 1.0 - *q.spray.energy_tolerance;
    sp.energy_ratio.high = 1.0 + *q.spray.energy_tolerance;
  }
  apply(q.spray.bright_fraction, sp.bright_fraction);
  // Targets the library leaves unset (judged only when the rig sets them), with its amber bands.
  using Spray = quicklook::ShadowTargets;
  if (q.spray.shadow_count)
    sp.shadow_count = quicklook::Target{(*q.spray.shadow_count)[0], (*q.spray.shadow_count)[1], Spray::shadow_count_amber};
  if (q.spray.min_intensity_max)
    sp.min_intensity = quicklook::Target{0.0, *q.spray.min_intensity_max, Spray::min_intensity_amber};
  apply(q.spray.binning, sh.binning);
  apply(q.spray.shadow_sigmas, sh.shadow_sigmas);
  apply(q.spray.reference_sets, sh.reference_sets);
  validate(sh, "quicklook.spray");
  return s;
}

std::string preview_endpoint(const std::vector<std::string>& given) {
  if (given.empty() || given.front().empty()) return stream::kDefaultPreviewEndpoint;
  return given.front();
}

StageSpec quicklook_stage_spec(const std::string& endpoint, const std::vector<StageSpec>& others) {
  for (const StageSpec& s : others)
    if (s.type == "quicklook")
      throw bad_input("--preview adds a quicklook stage, and --stage names one already: give either --preview or "
                      "--stage quicklook:publish=ENDPOINT");
  nlohmann::json table = {{"publish", endpoint}};
  return {"quicklook", StageTable(table, "quicklook")};
}

std::string quicklook_report_text(const StageReport& report) {
  if (report.name != "quicklook" || !report.status.is_object()) return {};
  const nlohmann::json& s = report.status;
  auto count = [&](const char* key) { return s.value(key, std::uint64_t{0}); };
  std::string text = fmt::format("quick-look: {} sets analysed, {} preview volumes ({} sets passed over)",
                                 count("analysed"), count("previews"), count("previews_skipped"));
  if (count("previews") > 0 && s.contains("preview_latency_s"))
    text += fmt::format(", each ready within {:.2f} s of its set", s["preview_latency_s"].value("max", 0.0));
  if (s.contains("publish") && s["publish"].is_string())
    text += fmt::format("; {} messages published on {}, {} dropped for slow viewers", count("published"),
                        s["publish"].get<std::string>(), count("dropped"));
  text += fmt::format("; {} sets stored in the session", count("stored"));
  if (count("drift_alarm_sets") > 0) text += fmt::format("; drift alarms in {} sets", count("drift_alarm_sets"));
  if (s.contains("preview") && s["preview"].is_string() && s["preview"].get<std::string>().starts_with("off:"))
    text += fmt::format("; preview {}", s["preview"].get<std::string>());
  if (s.contains("preview_error")) text += fmt::format("; last preview error: {}", s["preview_error"].get<std::string>());
  return text;
}

}  // namespace tomorig::pipeline
