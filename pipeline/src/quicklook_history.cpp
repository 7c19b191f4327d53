#include "tomorig/pipeline/quicklook_history.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace tomorig::pipeline {
namespace {

using storage::QuickLookCameraRecord;
using storage::QuickLookRecord;

FigureRange range_of(std::vector<double> values) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  FigureRange r;
  r.count = values.size();
  if (values.empty()) return r;
  std::sort(values.begin(), values.end());
  r.min = values.front();
  r.max = values.back();
  r.median = values[values.size() / 2];
  return r;
}

FigureRange over_sets(const std::vector<QuickLookRecord>& rows, const std::function<double(const QuickLookRecord&)>& f) {
  std::vector<double> v;
  for (const auto& r : rows) v.push_back(f(r));
  return range_of(std::move(v));
}

FigureRange over_camera(const std::vector<QuickLookRecord>& rows, std::size_t c,
                        const std::function<double(const QuickLookCameraRecord&)>& f) {
  std::vector<double> v;
  for (const auto& r : rows)
    if (c < r.cameras.size()) v.push_back(f(r.cameras[c]));
  return range_of(std::move(v));
}

void count_flag(std::uint8_t flag, std::uint64_t& green, std::uint64_t& amber, std::uint64_t& red) {
  (flag == 0 ? green : flag == 1 ? amber : red) += 1;
}

const char* flag_name(std::uint8_t flag) { return flag == 0 ? "green" : flag == 1 ? "amber" : "red"; }

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json range_json(const FigureRange& r) {
  if (r.count == 0) return nullptr;
  return {{"count", r.count}, {"min", r.min}, {"median", r.median}, {"max", r.max}};
}

std::string range_text(const FigureRange& r, const char* format) {
  if (r.count == 0) return "-";
  return fmt::format(fmt::runtime(std::string(format) + " [" + format + " to " + format + "]"), r.median, r.min,
                     r.max);
}

std::string value_text(float v, const char* format) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : std::string("-");
}

}  // namespace

QuickLookHistory quicklook_history(std::vector<QuickLookRecord> records,
                                   const std::vector<storage::SessionCamera>& cameras) {
  QuickLookHistory h;
  h.sets = records.size();
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    CameraHistory ch;
    ch.id = cameras[c].id;
    ch.ppp = over_camera(records, c, [](const auto& r) { return r.ppp[0]; });
    ch.diameter_px = over_camera(records, c, [](const auto& r) { return r.diameter_px[0]; });
    ch.source_density = over_camera(records, c, [](const auto& r) { return r.source_density[0]; });
    ch.saturated_fraction = over_camera(records, c, [](const auto& r) {
      return std::isfinite(r.saturated_fraction[1]) ? std::fmax(r.saturated_fraction[0], r.saturated_fraction[1])
                                                    : r.saturated_fraction[0];
    });
    ch.energy_balance = over_camera(records, c, [](const auto& r) { return r.energy_balance; });
    ch.dt_displacement_px = over_camera(records, c, [](const auto& r) { return r.dt_displacement_px; });
    ch.dt_valid_fraction = over_camera(records, c, [](const auto& r) { return r.dt_valid_fraction; });
    ch.drift_px = over_camera(records, c, [](const auto& r) { return r.drift_px; });
    for (const auto& r : records)
      if (c < r.cameras.size()) count_flag(r.cameras[c].flag, ch.green, ch.amber, ch.red);
    h.cameras.push_back(std::move(ch));
  }
  if (!records.empty()) {
    h.first_set = records.front().set_index;
    h.last_set = records.front().set_index;
  }
  for (const auto& r : records) {
    h.first_set = std::min(h.first_set, r.set_index);
    h.last_set = std::max(h.last_set, r.set_index);
    h.previews += r.preview ? 1 : 0;
    h.drift_alarm_sets += r.drift_alarms > 0 ? 1 : 0;
    count_flag(r.flag, h.green, h.amber, h.red);
  }
  h.sheet_position_mm = over_sets(records, [](const auto& r) { return r.sheet_position_mm; });
  h.sheet_thickness_mm = over_sets(records, [](const auto& r) { return r.sheet_thickness_mm; });
  h.ghost_front = over_sets(records, [](const auto& r) { return r.ghost_front; });
  h.ghost_back = over_sets(records, [](const auto& r) { return r.ghost_back; });
  h.rsnr = over_sets(records, [](const auto& r) { return r.rsnr; });
  h.records = std::move(records);
  return h;
}

QuickLookHistory quicklook_history(const storage::SessionReader& session) {
  return quicklook_history(session.quicklook(), session.info().cameras);
}

nlohmann::json to_json(const QuickLookHistory& h) {
  using nlohmann::json;
  json cameras = json::array();
  for (const CameraHistory& c : h.cameras)
    cameras.push_back({{"id", c.id},
                       {"ppp", range_json(c.ppp)},
                       {"diameter_px", range_json(c.diameter_px)},
                       {"source_density", range_json(c.source_density)},
                       {"saturated_fraction", range_json(c.saturated_fraction)},
                       {"energy_balance", range_json(c.energy_balance)},
                       {"dt_displacement_px", range_json(c.dt_displacement_px)},
                       {"dt_valid_fraction", range_json(c.dt_valid_fraction)},
                       {"drift_px", range_json(c.drift_px)},
                       {"flags", {{"green", c.green}, {"amber", c.amber}, {"red", c.red}}}});
  json history = json::array();
  for (const QuickLookRecord& r : h.records) {
    json cams = json::array();
    for (const QuickLookCameraRecord& c : r.cameras)
      cams.push_back({{"flag", flag_name(c.flag)},
                      {"ppp", {number(c.ppp[0]), number(c.ppp[1])}},
                      {"diameter_px", {number(c.diameter_px[0]), number(c.diameter_px[1])}},
                      {"source_density", {number(c.source_density[0]), number(c.source_density[1])}},
                      {"saturated_fraction", {number(c.saturated_fraction[0]), number(c.saturated_fraction[1])}},
                      {"background", {number(c.background[0]), number(c.background[1])}},
                      {"noise", {number(c.noise[0]), number(c.noise[1])}},
                      {"soft_tile_fraction", {number(c.soft_tile_fraction[0]), number(c.soft_tile_fraction[1])}},
                      {"energy_balance", number(c.energy_balance)},
                      {"dt_displacement_px", number(c.dt_displacement_px)},
                      {"dt_valid_fraction", number(c.dt_valid_fraction)},
                      {"drift_px", number(c.drift_px)}});
    history.push_back({{"set", r.set_index},
                       {"flag", flag_name(r.flag)},
                       {"preview", r.preview},
                       {"sheet_position_mm", number(r.sheet_position_mm)},
                       {"sheet_thickness_mm", number(r.sheet_thickness_mm)},
                       {"ghost_front", number(r.ghost_front)},
                       {"ghost_back", number(r.ghost_back)},
                       {"rsnr", number(r.rsnr)},
                       {"drift_alarms", r.drift_alarms},
                       {"cameras", std::move(cams)}});
  }
  return {{"sets", h.sets},
          {"previews", h.previews},
          {"first_set", h.sets == 0 ? json(nullptr) : json(h.first_set)},
          {"last_set", h.sets == 0 ? json(nullptr) : json(h.last_set)},
          {"flags", {{"green", h.green}, {"amber", h.amber}, {"red", h.red}}},
          {"drift_alarm_sets", h.drift_alarm_sets},
          {"cameras", std::move(cameras)},
          {"sheet",
           {{"position_mm", range_json(h.sheet_position_mm)},
            {"thickness_mm", range_json(h.sheet_thickness_mm)},
            {"ghost_front", range_json(h.ghost_front)},
            {"ghost_back", range_json(h.ghost_back)},
            {"rsnr", range_json(h.rsnr)}}},
          {"history", std::move(history)}};
}

std::string history_text(const QuickLookHistory& h, int rows) {
  if (h.sets == 0) return {};
  std::string out = fmt::format(
      "quick-look   {} set{} measured (sets {} to {}), {} with a preview volume; flags {} green, {} amber, {} red{}\n",
      h.sets, h.sets == 1 ? "" : "s", h.first_set, h.last_set, h.previews, h.green, h.amber, h.red,
      h.drift_alarm_sets > 0 ? fmt::format("; drift alarms in {} sets", h.drift_alarm_sets) : std::string());
  out += "  median [range] over the run (frame A):\n";
  for (const CameraHistory& c : h.cameras) {
    out += fmt::format("  {:<10} ppp {}  d_tau {} px  Ns {}\n", c.id, range_text(c.ppp, "{:.3f}"),
                       range_text(c.diameter_px, "{:.2f}"), range_text(c.source_density, "{:.2f}"));
    out += fmt::format("  {:<10} saturated {}  B/A {}  dt check {} px  drift {} px\n", "",
                       range_text(c.saturated_fraction, "{:.2g}"), range_text(c.energy_balance, "{:.2f}"),
                       range_text(c.dt_displacement_px, "{:.1f}"), range_text(c.drift_px, "{:.2f}"));
  }
  if (h.sheet_position_mm.count > 0)
    out += fmt::format("  sheet      at {} mm, {} mm thick; ghost level {} in front, {} behind; RSNR {}\n",
                       range_text(h.sheet_position_mm, "{:.3f}"), range_text(h.sheet_thickness_mm, "{:.3f}"),
                       range_text(h.ghost_front, "{:.2f}"), range_text(h.ghost_back, "{:.2f}"),
                       range_text(h.rsnr, "{:.1f}"));
  // A few rows spread over the run: the first, the last and evenly in between.
  const std::size_t n = h.records.size();
  const std::size_t shown = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(rows, 0)));
  if (shown == 0) return out;
  out += fmt::format("  {:>8}  {:<5}  {:>7}  {:>6}  {:>8}  {:>9}  {:>8}  {:>6}\n", "set", "flag", "ppp", "d_tau",
                     "dt px", "sheet mm", "thick mm", "alarms");
  for (std::size_t i = 0; i < shown; ++i) {
    const std::size_t k = shown == 1 ? 0 : i * (n - 1) / (shown - 1);
    const QuickLookRecord& r = h.records[k];
    // Means over the cameras that measured each figure.
    auto mean = [&](auto f) {
      double s = 0;
      int m = 0;
      for (const auto& c : r.cameras)
        if (std::isfinite(f(c))) {
          s += f(c);
          ++m;
        }
      return m > 0 ? static_cast<float>(s / m) : storage::kNotMeasured;
    };
    out += fmt::format("  {:>8}  {:<5}  {:>7}  {:>6}  {:>8}  {:>9}  {:>8}  {:>6}\n", r.set_index, flag_name(r.flag),
                       value_text(mean([](const auto& c) { return c.ppp[0]; }), "{:.3f}"),
                       value_text(mean([](const auto& c) { return c.diameter_px[0]; }), "{:.2f}"),
                       value_text(mean([](const auto& c) { return c.dt_displacement_px; }), "{:.1f}"),
                       value_text(r.sheet_position_mm, "{:+.3f}"), value_text(r.sheet_thickness_mm, "{:.3f}"),
                       r.drift_alarms > 0 ? fmt::format("{} !", r.drift_alarms) : std::string("-"));
  }
  return out;
}

}  // namespace tomorig::pipeline
