#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "decode.h"
#include "tomorig/core/camera_id.h"

namespace tomorig::config::detail {
namespace {

// Image sides and offsets: as the wire format allows (stream/wire_format.h), so that a ROI that
// passes here can be sent, recorded and allocated.
constexpr int kMaxImageSidePx = 1 << 16;

// GenICam names of the exposure time; the timing plan writes it, so a verbatim one must agree.
constexpr std::string_view kExposureFeatures[] = {"ExposureTime", "ExposureTimeAbs"};

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

// A verbatim exposure feature must say what the timing plan writes ([trigger.camera]
// exposure_a_us): two sources of one setting would leave the camera exposing for whichever
// came last, and the plan's frame windows would be fiction.
void check_exposure_feature(TableReader& features, const std::string& key, const std::string& value,
                            const CameraTimingConfig& timing) {
  double us = 0.0;
  const auto parsed = std::from_chars(value.data(), value.data() + value.size(), us);
  if (parsed.ec != std::errc() || parsed.ptr != value.data() + value.size()) {
    features.issue(key, fmt::format("\"{}\" is not a number of microseconds; the exposure comes from the timing plan "
                                    "([trigger.camera] exposure_a_us = {}): remove this feature",
                                    value, timing.exposure_a_us));
    return;
  }
  if (std::abs(us - timing.exposure_a_us) > 1e-6 * std::max(1.0, timing.exposure_a_us))
    features.issue(key, fmt::format("{} contradicts the timing plan, which writes {} = {} us from [trigger.camera] "
                                    "exposure_a_us; remove the feature or make the two equal",
                                    value, key, timing.exposure_a_us));
}

void decode_features(TableReader& cam, const CameraTimingConfig& timing, std::map<std::string, std::string>& features) {
  auto r = cam.table("features");
  if (!r) return;
  for (const auto& key : r->keys()) {
    std::string value;
    if (!r->read_as_text(key, value)) continue;
    features[key] = value;
    for (const auto name : kExposureFeatures)
      if (key == name) check_exposure_feature(*r, key, value, timing);
  }
  r->report_unknown_keys();  // none: every key is a feature name; kept for symmetry
}

void decode_camera(TableReader& r, const TriggerConfig& trigger, CameraConfig& cam) {
  r.read("id", cam.id, Need::required, not_empty());
  // Required, not defaulted: a rig that silently fell back to simulated cameras would
  // "record" synthetic images during a real run.
  CameraBackend backend{};
  const bool backend_known = r.read_choice("backend", backend, Need::required);
  if (backend_known) cam.backend = backend;
  const bool aravis = backend_known && backend == CameraBackend::aravis;
  const bool gentl = backend_known && backend == CameraBackend::gentl;
  const bool simulated = backend_known && backend == CameraBackend::simulated;

  r.read("device_id", cam.device_id, aravis || gentl ? Need::required : Need::optional, not_empty());
  if (cam.device_id.empty() && simulated) cam.device_id = cam.id;
  // The producer is checked when the camera opens (it may live on the acquisition host only).
  std::string producer;
  if (r.read("producer", producer, Need::optional, not_empty())) {
    if (backend_known && !gentl)
      r.issue("producer", "is for backend = \"gentl\" cameras (the GenTL producer's .cti file); remove it");
    cam.producer = producer;
  }

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
  decode_features(r, trigger.camera, cam.features);

  if (r.read_choice("frame_mode", cam.frame_mode)) {
    if (cam.frame_mode == FrameMode::two_triggers && trigger.camera.readout_us <= 0.0)
      r.issue("frame_mode", "\"two_triggers\" needs the camera's readout time: add readout_us to [trigger.camera] (the "
                            "least time from the end of one exposure to the next trigger the camera takes, about "
                            "1 / its top frame rate at this ROI)");
    if (cam.frame_mode == FrameMode::free_run && simulated)
      r.issue("frame_mode", "\"free_run\" is for aravis and gentl cameras; a simulated camera is exposed by every trigger event "
                            "(use \"hardware\" or \"two_triggers\")");
  }

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

void decode_cameras(TableReader& root, const TriggerConfig& trigger, std::vector<CameraConfig>& cameras) {
  struct FirstUse {
    std::string path;
    int line;
  };
  std::map<std::string, FirstUse> ids;
  // The triggered cameras share the trigger's camera channel, so they share one frame mode;
  // free-running cameras are not triggered and may be mixed in.
  std::optional<std::pair<FrameMode, std::string>> triggered_mode;
  for (auto& r : root.array_of_tables("cameras", Need::required)) {
    CameraConfig cam;
    decode_camera(r, trigger, cam);
    // One rule for ids everywhere (core/camera_id.h); the value is shown escaped, never raw.
    if (const auto problem = cam.id.empty() ? std::nullopt : camera_id_problem(cam.id)) {
      r.issue("id", fmt::format("\"{}\" is not allowed: it {} (camera ids name folders in session files: 1 to {} "
                                "bytes of UTF-8 without '/', control characters, '.' or '..')",
                                printable(cam.id), *problem, kMaxCameraIdBytes));
      cam.id.clear();
    }
    if (cam.frame_mode != FrameMode::free_run) {
      if (!triggered_mode) {
        triggered_mode.emplace(cam.frame_mode, r.path());
      } else if (triggered_mode->first != cam.frame_mode) {
        r.issue("frame_mode", fmt::format("\"{}\" differs from {} (\"{}\"): the triggered cameras share one camera "
                                          "trigger, so give them one frame_mode (only \"free_run\" cameras may differ)",
                                          to_string(cam.frame_mode), triggered_mode->second,
                                          to_string(triggered_mode->first)));
      }
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
