#pragma once
// Quick-look messages as the quick-look stage sends them (docs/wire-protocol.md, "Quick-look
// messages"), small enough to write by hand: JSON part plus real PNG parts.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tomorig/core/image.h"
#include "tomorig/storage/image_file.h"
#include "tomorig/stream/preview.h"

namespace tomorig::testing {

// A grey ramp, so the PNG decodes to something other than a blank.
inline std::string ramp_png(int width, int height) {
  Image image = Image::allocate(width, height, SampleType::u8);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) image.at<std::uint8_t>(x, y) = static_cast<std::uint8_t>((x * 255) / width);
  return storage::encode_png(image);
}

inline nlohmann::json judged(double value, const char* flag) { return {{"value", value}, {"flag", flag}}; }

inline stream::PreviewMessage quicklook_message(std::uint64_t set, double ppp = 0.05, int cameras = 1,
                                                int thumbnail_px = 16) {
  using nlohmann::json;
  json frame = {{"particles", {{"ppp", judged(ppp, "green")}, {"diameter_px", judged(2.4, "green")},
                               {"source_density", judged(0.2, "green")}}},
                {"saturation", {{"fraction", judged(0.0, "green")},
                                {"map", {{"tiles_x", 2}, {"tiles_y", 1}, {"tile_px", 64}, {"values", {0, 0}}}}}},
                {"histogram", {{"bin_width", 1.0}, {"counts", {5, 4, 3, 2, 1}}}}};
  json cam = {{"id", "cam0"},
              {"flag", "green"},
              {"statistics", {{"a", frame}, {"b", frame}, {"energy_balance", judged(1.0, "green")}}},
              {"dt_check", {{"displacement_px", judged(5.0, "green")}, {"valid_fraction", judged(0.9, "green")},
                            {"windows", json::array({{{"dx", 1.0}}})}}}};
  json all = json::array(), images = json::array();
  std::vector<std::string> parts;
  for (int c = 0; c < cameras; ++c) {
    const std::string id = "cam" + std::to_string(c);
    cam["id"] = id;
    all.push_back(cam);
    images.push_back({{"name", id + "/a"}, {"kind", "thumbnail"}, {"part", parts.size() + 1}, {"width", thumbnail_px},
                      {"height", thumbnail_px / 2}});
    parts.push_back(ramp_png(thumbnail_px, thumbnail_px / 2));
    images.push_back({{"name", id + "/histogram"}, {"kind", "histogram"}, {"part", parts.size() + 1}, {"width", 5},
                      {"height", 4}});
    parts.push_back(ramp_png(5, 4));
  }
  json j = {{"type", "tomorig.quicklook"}, {"version", 1}, {"time_ns", 1}, {"set", set}, {"trigger_index", set},
            {"dt_ns", 100000}, {"flag", "green"}, {"cameras", all}, {"preview", nullptr}, {"drift", nullptr},
            {"counts", {{"analysed", set + 1}}}, {"images", images}};
  return {j.dump(), parts};
}

inline stream::PreviewMessage preview_message(std::uint64_t set) {
  using nlohmann::json;
  json sheet = {{"found", true}, {"position_mm", 0.01}, {"thickness_mm", 3.0}, {"low_edge_mm", -1.5},
                {"high_edge_mm", 1.5}, {"ghost_front", 0.1}, {"ghost_back", 0.1}, {"rsnr", 9.0}, {"flag", "green"},
                {"z0_mm", -3.0}, {"dz_mm", 0.5}, {"profile", {0.1, 0.2, 1.0, 0.9, 0.2}}};
  json j = {{"type", "tomorig.preview"}, {"version", 1}, {"time_ns", 1}, {"set", set}, {"latency_s", 0.3},
            {"preview", {{"sheet", sheet}, {"active_voxels", 100}}}, {"drift", nullptr},
            {"images", {{{"name", "mip_z"}, {"kind", "mip"}, {"part", 1}, {"width", 12}, {"height", 12}}}}};
  return {j.dump(), {ramp_png(12, 12)}};
}

}  // namespace tomorig::testing
