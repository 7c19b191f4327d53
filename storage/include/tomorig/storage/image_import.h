#pragma once
// Building a session from image sequences recorded by other software: one glob pattern per
// camera (e.g. "cam0.pre/im*.tif"), frames paired into sets by name or by order. The result
// is an ordinary session file, so everything downstream treats imported and recorded runs
// alike.
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "tomorig/core/pixel_format.h"
#include "tomorig/storage/session_file.h"

namespace tomorig::storage {

enum class FramePairing : std::uint8_t {
  automatic,  // by name if every file name ends in a/b before the extension, else by order
  by_name,    // "im00001a.tif" + "im00001b.tif" form a set (case-insensitive a/b)
  by_order,   // consecutive frames form a set: A, B, A, B, ... (files in natural order, pages in order)
};
std::string_view to_string(FramePairing pairing);  // "auto", "name", "order"
std::optional<FramePairing> parse_frame_pairing(std::string_view name);

struct ImportCamera {
  std::string id;       // session camera id, e.g. "cam0"
  std::string pattern;  // glob (*, ?, [..]); may name a single multi-page TIFF
  // Default: Mono8 for 8-bit files, Mono16 for 16-bit. Set Mono12 for 12-bit data stored in
  // 16-bit files; a format whose sample size differs from the files' is an error.
  std::optional<PixelFormat> pixel_format;
  double pixel_pitch_um = 0.0;  // sensor pixel pitch; 0 = unknown
};

struct ImportOptions {
  std::vector<ImportCamera> cameras;  // in session order
  FramePairing pairing = FramePairing::automatic;
  double dt_us = 0.0;    // pulse separation A -> B, recorded for every set; 0 = unknown
  // Trigger rate used to synthesise trigger timestamps (set i at i / rate_hz); 0 = unknown,
  // all sets at t = 0. Frame A is stamped at the trigger time, frame B dt later.
  double rate_hz = 0.0;
  std::string rig_config_toml;  // stored as /config (may be empty)
  SessionWriterOptions writer;
};

// One frame of a source sequence: a file and the page within it.
struct ImageSource {
  std::filesystem::path file;
  int page = 0;
  int pages = 1;  // pages in the file, so messages can say "page 3 of 10"
  std::string to_string() const;  // "cam0/im00001a.tif" or "cam0/seq.tif (page 3 of 10)"
};

// Files found and frames paired, before any pixels are read.
struct ImportPlan {
  struct Camera {
    std::string id;
    std::string pattern;
    std::vector<std::filesystem::path> files;       // in natural order ("im2" before "im10")
    std::vector<std::array<ImageSource, 2>> sets;   // [0] frame A, [1] frame B
  };
  FramePairing pairing = FramePairing::by_name;  // as resolved: by_name or by_order, never automatic
  std::vector<Camera> cameras;
  std::uint64_t set_count() const { return cameras.empty() ? 0 : cameras.front().sets.size(); }
};

// Throws bad_input naming the pattern or file: no cameras, duplicate ids, a pattern that
// matches nothing, a frame without a partner, an odd frame count, or cameras with different
// numbers of sets.
ImportPlan plan_image_import(const ImportOptions& options);

struct ImportResult {
  ImportPlan plan;
  std::vector<SessionCamera> cameras;  // as written
  std::uint64_t sets = 0;
  std::filesystem::path output;
};

// Plans, reads every frame and writes the session to `output` (via "<output>.partial", so a
// failed import leaves nothing behind). Besides the planning errors, throws bad_input naming
// the file when a frame cannot be read, is not single-channel 8/16-bit, or differs in size
// from the other frames (all cameras must share one size) or in sample type from its
// camera's other frames.
ImportResult import_images(const ImportOptions& options, const std::filesystem::path& output);

}  // namespace tomorig::storage
