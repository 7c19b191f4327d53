#pragma once
// The quick-look numbers of one set as a session file keeps them (/quicklook, layout in
// docs/file-formats.md): a few figures per camera and per set, small enough to store for every
// set of a long run, so `tomorig inspect` can show how seeding, illumination, Δt, alignment and
// the light sheet went. NaN: not measured (e.g. the preview volume skipped that set). Flags:
// 0 green, 1 amber, 2 red. Storage knows nothing of how they are measured (processing/quicklook).
#include <cstdint>
#include <limits>
#include <string_view>
#include <vector>

namespace tomorig::storage {

inline constexpr float kNotMeasured = std::numeric_limits<float>::quiet_NaN();

struct QuickLookCameraRecord {
  std::uint8_t flag = 2;  // the camera's worst figure
  // Per exposure, [0] frame A, [1] frame B.
  float ppp[2] = {kNotMeasured, kNotMeasured};
  float diameter_px[2] = {kNotMeasured, kNotMeasured};
  float source_density[2] = {kNotMeasured, kNotMeasured};
  float saturated_fraction[2] = {kNotMeasured, kNotMeasured};
  float background[2] = {kNotMeasured, kNotMeasured};  // counts
  float noise[2] = {kNotMeasured, kNotMeasured};       // counts, 1 sigma
  float soft_tile_fraction[2] = {kNotMeasured, kNotMeasured};
  float energy_balance = kNotMeasured;      // B over A
  float dt_displacement_px = kNotMeasured;  // Δt check: median displacement of the valid windows
  float dt_valid_fraction = kNotMeasured;
  float drift_px = kNotMeasured;            // drift monitor: largest sub-volume disparity
};

struct QuickLookRecord {
  std::uint64_t set_index = 0;  // the set these figures are of (session set index)
  std::uint8_t flag = 2;        // the set's worst figure
  // The preview volume, when this set got one.
  bool preview = false;
  float sheet_position_mm = kNotMeasured;
  float sheet_thickness_mm = kNotMeasured;
  float ghost_front = kNotMeasured;
  float ghost_back = kNotMeasured;
  float rsnr = kNotMeasured;
  std::uint16_t drift_alarms = 0;  // sub-volumes over the drift limit, all cameras
  std::vector<QuickLookCameraRecord> cameras;  // session camera order
};

// The column names of /quicklook/sets and /quicklook/cameras, in order (docs/file-formats.md).
const std::vector<std::string_view>& quicklook_set_columns();
const std::vector<std::string_view>& quicklook_camera_columns();

}  // namespace tomorig::storage
