#include <map>
#include <string>

#include <fmt/format.h>

#include "decode.h"
#include "tomorig/core/camera_id.h"

namespace tomorig::config::detail {
namespace {

// Image sides and offsets: as the wire format allows (stream/wire_format.h), so that a ROI that
// passes here can be sent, recorded and allocated.
constexpr int kMaxImageSidePx = 1 << 16;

constexpr Choice<CameraBackend> kCameraBackends[] = {
    {"aravis", CameraBackend::aravis}, {"simulated", CameraBackend::simulated}};

void decode_roi(TableReader& cam, bool simulated, Roi& roi) {
  // A simulated camera has no sensor to ask for its size, so the ROI is the image size.
  if (simulated && !cam.has("roi")) {
    cam.issue("roi", "required for simulated cameras (the image size): add [cameras.roi] with width and height");
    return;
  }
  auto r = cam.table("roi");
  if (!r) return;
  r->read("offset_x", roi.offset_x, Need::optional, and_at_most(at_least(0), kMaxImageSidePx));
  r->read("offset_y", roi.offset_y, Need::optional, and_at_most(at_least(0), kMaxImageSidePx));
  r->read("width", roi.width, Need::required, and_at_most(greater_than(0), kMaxImageSidePx));
  r->read("height", roi.height, Need::required, and_at_most(greater_than(0), kMaxImageSidePx));
  r->report_unknown_keys();
}

void decode_features(TableReader& cam, std::map<std::string, std::string>& features) {
  auto r = cam.table("features");
  if (!r) return;
  for (const auto& key : r->keys()) {
    std::string value;
    if (r->read_as_text(key, value)) features[key] = value;
  }
  r->report_unknown_keys();  // none: every key is a feature name; kept for symmetry
}

void decode_camera(TableReader& r, CameraConfig& cam) {
  r.read("id", cam.id, Need::required, not_empty());
  // Required, not defaulted: a rig that silently fell back to simulated cameras would
  // "record" synthetic images during a real run.
  CameraBackend backend{};
  const bool backend_known = r.read_choice("backend", backend, kCameraBackends, Need::required);
  if (backend_known) cam.backend = backend;
  const bool aravis = backend_known && backend == CameraBackend::aravis;
  const bool simulated = backend_known && backend == CameraBackend::simulated;

  r.read("device_id", cam.device_id, aravis ? Need::required : Need::optional, not_empty());
  if (cam.device_id.empty() && simulated) cam.device_id = cam.id;

  std::string format;
  if (r.read("pixel_format", format)) {
    if (auto parsed = parse_pixel_format(format)) {
      cam.pixel_format = *parsed;
    } else {
      r.issue("pixel_format", fmt::format("\"{}\" is not supported ({})", format, supported_pixel_formats()));
    }
  }
  r.read("pixel_pitch_um", cam.pixel_pitch_um, Need::optional, greater_than(0.0));
  decode_roi(r, simulated, cam.roi);
  decode_features(r, cam.features);

  r.read("yaw_deg", cam.yaw_deg, Need::optional, in_closed(-180.0, 180.0));
  const bool focal_ok =
      valid_or_absent(r, "focal_length_mm", r.read("focal_length_mm", cam.focal_length_mm, Need::optional, greater_than(0.0)));
  const bool distance_ok =
      valid_or_absent(r, "distance_mm", r.read("distance_mm", cam.distance_mm, Need::optional, greater_than(0.0)));
  // The pinhole sits at distance_mm from the origin; inside the focal length it cannot image it.
  if (simulated && focal_ok && distance_ok && cam.distance_mm <= cam.focal_length_mm) {
    r.issue("distance_mm", fmt::format("{} must be > focal_length_mm ({})", cam.distance_mm, cam.focal_length_mm));
  }
  r.report_unknown_keys();
}

}  // namespace

void decode_cameras(TableReader& root, std::vector<CameraConfig>& cameras) {
  struct FirstUse {
    std::string path;
    int line;
  };
  std::map<std::string, FirstUse> ids;
  for (auto& r : root.array_of_tables("cameras", Need::required)) {
    CameraConfig cam;
    decode_camera(r, cam);
    // One rule for ids everywhere (core/camera_id.h); the value is shown escaped, never raw.
    if (const auto problem = cam.id.empty() ? std::nullopt : camera_id_problem(cam.id)) {
      r.issue("id", fmt::format("\"{}\" is not allowed: it {} (camera ids name folders in session files: 1 to {} "
                                "bytes of UTF-8 without '/', control characters, '.' or '..')",
                                printable(cam.id), *problem, kMaxCameraIdBytes));
      cam.id.clear();
    }
    if (!cam.id.empty()) {
      auto [it, inserted] = ids.try_emplace(cam.id, FirstUse{r.path(), r.line_of("id")});
      if (!inserted) {
        r.issue("id", fmt::format("\"{}\" is already used by {} (line {}); camera ids must be unique", cam.id,
                                  it->second.path, it->second.line));
      }
    }
    cameras.push_back(std::move(cam));
  }
}

}  // namespace tomorig::config::detail
