#include "tomorig/processing/quicklook/json.h"

#include <cmath>

#include <nlohmann/json.hpp>

namespace tomorig::quicklook {
namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json point(const Vec3d& p) { return nlohmann::json::array({p.x, p.y, p.z}); }

}  // namespace

void to_json(nlohmann::json& j, Flag flag) { j = std::string(to_string(flag)); }

void to_json(nlohmann::json& j, const Judged& judged) { j = {{"value", number(judged.value)}, {"flag", judged.flag}}; }

void to_json(nlohmann::json& j, const TileMap& map) {
  nlohmann::json values = nlohmann::json::array();
  for (const float v : map.values) values.push_back(number(v));
  j = {{"tiles_x", map.tiles_x}, {"tiles_y", map.tiles_y}, {"tile_px", map.tile_px}, {"values", std::move(values)}};
}

void to_json(nlohmann::json& j, const FrameStatistics& s) {
  const Percentiles& p = s.percentiles;
  j = {
      {"width", s.width},
      {"height", s.height},
      {"full_scale", s.full_scale},
      {"mean", number(s.mean)},
      {"mean_excess", number(s.mean_excess)},
      {"percentiles", {{"p1", p.p1}, {"p5", p.p5}, {"p50", p.p50}, {"p95", p.p95}, {"p99", p.p99}, {"p99.9", p.p999}}},
      {"histogram", {{"bin_width", s.histogram_bin_width}, {"counts", s.histogram}}},
      {"background",
       {{"level", number(s.background)},
        {"noise", number(s.noise)},
        {"p5", number(s.background_p5)},
        {"p50", number(s.background_p50)},
        {"p95", number(s.background_p95)},
        {"map", s.background_map}}},
      {"saturation", {{"fraction", s.saturated_fraction}, {"map", s.saturation_map}}},
      {"particles",
       {{"maxima_per_pixel", number(s.maxima_per_pixel)},
        {"ppp_autocovariance", number(s.ppp_autocovariance)},
        {"ppp", s.ppp},
        {"diameter_px", s.diameter_px},
        {"source_density", s.source_density}}},
      {"focus", {{"map", s.focus_map}, {"soft_tile_fraction", s.soft_tile_fraction}}},
      {"flag", s.overall()},
  };
}

void to_json(nlohmann::json& j, const CameraQuickLook& s) {
  j = {{"a", s.a}, {"b", s.b}, {"energy_balance", s.energy_balance}, {"flag", s.overall()}};
}

void to_json(nlohmann::json& j, const ShadowFrame& s) {
  // count, min_intensity and fraction stay plain numbers (viewers read them so); their flags
  // against the rig's targets sit beside them.
  j = {{"width", s.width},
       {"height", s.height},
       {"binning", s.binning},
       {"bright_field",
        {{"level", number(s.bright_level)},
         {"fraction", number(s.bright_fraction.value)},
         {"fraction_flag", s.bright_fraction.flag},
         {"noise", number(s.noise)},
         {"working_noise", number(s.working_noise)},
         {"uniformity", s.uniformity},
         {"map", s.level_map}}},
       {"shadows",
        {{"threshold", number(s.threshold)},
         {"coverage", s.shadow_coverage},
         {"count", static_cast<std::uint64_t>(s.shadows.value)},
         {"count_flag", s.shadows.flag},
         {"per_mpx", number(s.shadows_per_mpx)},
         {"min_intensity", number(s.min_intensity.value)},
         {"min_intensity_flag", s.min_intensity.flag},
         {"spray_tile_fraction", s.spray_tile_fraction},
         {"map", s.coverage_map}}},
       {"flag", s.overall()}};
}

void to_json(nlohmann::json& j, const ShadowCameraLook& s) {
  j = {{"a", s.a},
       {"b", s.b},
       {"energy_ratio", s.energy_ratio},
       {"history", s.reference_ready ? nlohmann::json{{"a", s.history_a}, {"b", s.history_b}} : nlohmann::json(nullptr)},
       {"led_energy_alarms", s.alarms},
       {"flag", s.overall()}};
}

void to_json(nlohmann::json& j, const DtCheckResult& r) {
  nlohmann::json windows = nlohmann::json::array();
  for (const DtWindow& w : r.windows)
    windows.push_back({{"x0", w.x0},
                       {"y0", w.y0},
                       {"dx", number(w.dx)},
                       {"dy", number(w.dy)},
                       {"correlation", number(w.correlation)},
                       {"peak_ratio", number(w.peak_ratio)},
                       {"valid", w.valid}});
  j = {{"valid_fraction", r.valid_fraction},
       {"median_peak_ratio", number(r.median_peak_ratio)},
       {"displacement_px", r.displacement_px},
       {"median_dx", number(r.median_dx)},
       {"median_dy", number(r.median_dy)},
       {"displacement_histogram", r.displacement_histogram},
       {"windows", std::move(windows)},
       {"flag", r.overall()}};
}

void to_json(nlohmann::json& j, const DriftReport& r) {
  nlohmann::json cameras = nlohmann::json::array();
  for (std::size_t c = 0; c < r.cameras.size(); ++c) {
    nlohmann::json subvolumes = nlohmann::json::array();
    for (const SubvolumeDrift& s : r.cameras[c])
      subvolumes.push_back({{"index", {s.i, s.j, s.k}},
                            {"centre_mm", point(s.centre)},
                            {"disparity_px", {s.disparity.x, s.disparity.y}},
                            {"support", s.support},
                            {"valid", s.valid}});
    cameras.push_back({{"largest_px", r.largest_px[c]},
                       {"valid_subvolumes", r.valid_subvolumes[c]},
                       {"subvolumes", std::move(subvolumes)}});
  }
  nlohmann::json alarms = nlohmann::json::array();
  for (const DriftAlarm& a : r.alarms)
    alarms.push_back({{"camera", a.camera},
                      {"camera_index", a.camera_index},
                      {"subvolume", {a.subvolume.i, a.subvolume.j, a.subvolume.k}},
                      {"disparity_px", a.subvolume.magnitude()},
                      {"message", a.message}});
  j = {{"sets", r.sets}, {"matches", r.matches}, {"cameras", std::move(cameras)}, {"alarms", std::move(alarms)},
       {"flag", r.flag}};
}

void to_json(nlohmann::json& j, const SheetProfile& s) {
  nlohmann::json profile = nlohmann::json::array();
  for (const double v : s.intensity) profile.push_back(number(v));
  j = {{"found", s.found},
       {"position_mm", number(s.position_mm)},
       {"thickness_mm", number(s.thickness_mm)},
       {"low_edge_mm", number(s.low_edge_mm)},
       {"high_edge_mm", number(s.high_edge_mm)},
       {"ghost_front", number(s.ghost_front)},
       {"ghost_back", number(s.ghost_back)},
       {"rsnr", number(s.rsnr)},
       {"flag", s.flag},
       {"z0_mm", s.z_mm.empty() ? nlohmann::json(nullptr) : nlohmann::json(s.z_mm.front())},
       {"dz_mm", s.z_mm.size() < 2 ? nlohmann::json(nullptr) : nlohmann::json(s.z_mm[1] - s.z_mm[0])},
       {"profile", std::move(profile)}};
}

void to_json(nlohmann::json& j, const PreviewResult& r) {
  const VoxelGrid& g = r.grid;
  j = {{"grid",
        {{"nx", g.nx}, {"ny", g.ny}, {"nz", g.nz}, {"voxel_mm", g.voxel_size}, {"origin_mm", point(g.origin)}}},
       {"active_voxels", r.active_voxels},
       {"reconstruction_seconds", r.reconstruction_seconds},
       {"seconds", r.seconds},
       {"sheet", r.sheet}};
}

}  // namespace tomorig::quicklook
