#include "quicklook_report.h"

#include <chrono>
#include <cmath>

#include "tomorig/processing/quicklook/display.h"
#include "tomorig/processing/quicklook/json.h"
#include "tomorig/storage/image_file.h"

namespace tomorig::pipeline::quicklook_stage {
namespace {

using nlohmann::json;
using quicklook::Flag;

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Adds `image` as the next PNG part and its entry in "images".
void attach(stream::PreviewMessage& message, json& images, const Image& image, json entry) {
  entry["width"] = image.width();
  entry["height"] = image.height();
  entry["part"] = message.images.size() + 1;
  images.push_back(std::move(entry));
  message.images.push_back(storage::encode_png(image));
}

std::uint8_t flag_code(Flag f) { return static_cast<std::uint8_t>(f); }
float as_float(double v) { return static_cast<float>(v); }

// The display histogram's picture: as many columns as bins (up to 256), 64 rows.
constexpr int kHistogramHeight = 64;

}  // namespace

Flag CameraResult::flag() const {
  if (!measured) return Flag::red;
  if (shadow) return shadow_look.overall();
  return quicklook::worst(statistics.overall(), dt_check.overall());
}

json to_json(const PreviewSummary& p) {
  if (!p.available) return nullptr;
  const quicklook::SheetProfile& s = p.sheet;
  return {{"set", p.set},
          {"found", s.found},
          {"position_mm", number(s.position_mm)},
          {"thickness_mm", number(s.thickness_mm)},
          {"ghost_front", number(s.ghost_front)},
          {"ghost_back", number(s.ghost_back)},
          {"rsnr", number(s.rsnr)},
          {"flag", s.flag},
          {"active_voxels", p.active_voxels},
          {"seconds", p.seconds},
          {"latency_s", p.latency_s}};
}

json to_json(const DriftSummary& d) {
  if (!d.available) return nullptr;
  json largest = json::array();
  for (const double v : d.largest_px) largest.push_back(number(v));
  return {{"set", d.set}, {"sets", d.sets}, {"flag", d.flag}, {"largest_px", largest}, {"alarms", d.alarms}};
}

json to_json(const Counts& c) {
  return {{"analysed", c.analysed},
          {"skipped", c.skipped},
          {"previews", c.previews},
          {"previews_skipped", c.previews_skipped},
          {"drift_alarm_sets", c.drift_alarm_sets},
          {"published", c.published},
          {"dropped", c.dropped},
          {"stored", c.stored}};
}

stream::PreviewMessage set_message(const FrameSet& set, const std::vector<CameraResult>& cameras,
                                   const PreviewSummary& preview, const DriftSummary& drift, const Counts& counts,
                                   int thumbnail_px) {
  stream::PreviewMessage message;
  json images = json::array();
  json cams = json::array();
  Flag overall = Flag::green;
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const CameraResult& r = cameras[c];
    overall = quicklook::worst(overall, r.flag());
    json cam = {{"id", r.id}, {"flag", r.flag()}};
    if (r.measured && r.shadow) {
      cam["statistics"] = nullptr;
      cam["dt_check"] = nullptr;
      cam["shadow"] = r.shadow_look;
    } else if (r.measured) {
      cam["statistics"] = r.statistics;
      cam["dt_check"] = r.dt_check;
    } else {
      cam["statistics"] = nullptr;
      cam["dt_check"] = nullptr;
      cam["missing"] = r.missing;
    }
    cams.push_back(std::move(cam));
    const Frame& a = set.cameras[c].a;
    if (a.present()) {
      attach(message, images, quicklook::thumbnail(a.image, thumbnail_px),
             {{"name", r.id + "/a"}, {"kind", "thumbnail"}, {"camera", r.id}});
      if (r.measured && !r.shadow) {
        const auto& h = r.statistics.a.histogram;
        attach(message, images, quicklook::histogram_image(h, static_cast<int>(std::min<std::size_t>(h.size(), 256)),
                                                           kHistogramHeight),
               {{"name", r.id + "/histogram"}, {"kind", "histogram"}, {"camera", r.id},
                {"bin_width", r.statistics.a.histogram_bin_width}});
      }
    }
  }
  const json j = {{"type", "tomorig.quicklook"},
                  {"version", kMessageVersion},
                  {"time_ns", now_ns()},
                  {"set", set.set_index},
                  {"trigger_index", set.trigger_index},
                  {"dt_ns", set.dt_ns},
                  {"flag", overall},
                  {"cameras", std::move(cams)},
                  {"preview", to_json(preview)},
                  {"drift", to_json(drift)},
                  {"counts", to_json(counts)},
                  {"images", std::move(images)}};
  message.json = j.dump();
  return message;
}

stream::PreviewMessage preview_message(std::uint64_t set, const quicklook::PreviewResult& preview,
                                       const quicklook::DriftReport* drift, double latency_s, const Counts& counts) {
  stream::PreviewMessage message;
  json images = json::array();
  const struct {
    const Image* image;
    const char* name;
    const char* axes;
  } mips[] = {{&preview.mip_z, "mip_z", "x right, y down"},
              {&preview.mip_y, "mip_y", "x right, z down"},
              {&preview.mip_x, "mip_x", "y right, z down"}};
  for (const auto& m : mips)
    if (!m.image->empty())
      attach(message, images, quicklook::stretch_to_8bit(*m.image),
             {{"name", m.name}, {"kind", "mip"}, {"axes", m.axes}});
  const json j = {{"type", "tomorig.preview"},
                  {"version", kMessageVersion},
                  {"time_ns", now_ns()},
                  {"set", set},
                  {"latency_s", latency_s},
                  {"preview", preview},
                  {"drift", drift != nullptr ? json(*drift) : json(nullptr)},
                  {"counts", to_json(counts)},
                  {"images", std::move(images)}};
  message.json = j.dump();
  return message;
}

storage::QuickLookRecord statistics_record(std::uint64_t set, const std::vector<CameraResult>& cameras) {
  storage::QuickLookRecord r;
  r.set_index = set;
  Flag overall = Flag::green;
  for (const CameraResult& cam : cameras) {
    storage::QuickLookCameraRecord c;
    c.flag = flag_code(cam.flag());
    overall = quicklook::worst(overall, cam.flag());
    if (cam.measured && cam.shadow) {
      // The particle columns hold the shadow figures that share their meaning: the bright
      // field as the background and its noise, pulse B over A as the energy balance.
      const quicklook::ShadowFrame* frames[2] = {&cam.shadow_look.a, &cam.shadow_look.b};
      for (int e = 0; e < 2; ++e) {
        c.background[e] = as_float(frames[e]->bright_level);
        c.noise[e] = as_float(frames[e]->noise * frames[e]->bright_level);
      }
      c.energy_balance = as_float(cam.shadow_look.energy_ratio.value);
    } else if (cam.measured) {
      const quicklook::FrameStatistics* frames[2] = {&cam.statistics.a, &cam.statistics.b};
      for (int e = 0; e < 2; ++e) {
        const quicklook::FrameStatistics& f = *frames[e];
        c.ppp[e] = as_float(f.ppp.value);
        c.diameter_px[e] = as_float(f.diameter_px.value);
        c.source_density[e] = as_float(f.source_density.value);
        c.saturated_fraction[e] = as_float(f.saturated_fraction.value);
        c.background[e] = as_float(f.background);
        c.noise[e] = as_float(f.noise);
        c.soft_tile_fraction[e] = as_float(f.soft_tile_fraction.value);
      }
      c.energy_balance = as_float(cam.statistics.energy_balance.value);
      c.dt_displacement_px = as_float(cam.dt_check.displacement_px.value);
      c.dt_valid_fraction = as_float(cam.dt_check.valid_fraction.value);
    }
    r.cameras.push_back(c);
  }
  r.flag = flag_code(overall);
  return r;
}

storage::QuickLookRecord preview_record(std::uint64_t set, std::size_t cameras, const quicklook::PreviewResult* preview,
                                        const quicklook::DriftReport* drift) {
  storage::QuickLookRecord r;
  r.set_index = set;
  r.cameras.resize(cameras);
  Flag overall = Flag::green;
  if (preview != nullptr) {
    const quicklook::SheetProfile& s = preview->sheet;
    r.preview = true;
    r.sheet_position_mm = as_float(s.position_mm);
    r.sheet_thickness_mm = as_float(s.thickness_mm);
    r.ghost_front = as_float(s.ghost_front);
    r.ghost_back = as_float(s.ghost_back);
    r.rsnr = as_float(s.rsnr);
    overall = quicklook::worst(overall, s.flag);
  }
  for (auto& c : r.cameras) c.flag = flag_code(Flag::green);
  if (drift != nullptr) {
    overall = quicklook::worst(overall, drift->flag);
    r.drift_alarms = static_cast<std::uint16_t>(std::min<std::size_t>(drift->alarms.size(), 65535));
    for (std::size_t c = 0; c < cameras && c < drift->largest_px.size(); ++c)
      r.cameras[c].drift_px = as_float(drift->largest_px[c]);
    for (const quicklook::DriftAlarm& a : drift->alarms)
      if (a.camera_index >= 0 && static_cast<std::size_t>(a.camera_index) < cameras)
        r.cameras[static_cast<std::size_t>(a.camera_index)].flag = flag_code(Flag::red);
  }
  r.flag = flag_code(overall);
  return r;
}

}  // namespace tomorig::pipeline::quicklook_stage
