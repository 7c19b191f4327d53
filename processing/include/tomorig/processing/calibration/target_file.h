#pragma once
// A target description file (`tomorig calibrate --target-file T.toml`, docs/calibration.md,
// "Target description file"): what the plate looks like, written once per plate instead of
// repeated on every command line.
//
//   kind = "dots"              # dots or chessboard
//   pitch_mm = 2.0             # dots: distance of neighbouring dots of one level along x, y
//                              #       (the row pitch); chessboard: the square size
//   lattice = "staggered"      # dots: square (default) or staggered
//   level_offset_mm = -1.0     # staggered: z of the second level relative to the origin's
//   dots = "white"             # dots: white (on black, default) or black
//   y_axis = "down"            # dots: down, up or auto (default)
//   origin_mm = [0, 0, 0]      # dots: world position of the origin site (default 0, 0, 0)
//   max_feature_px = 0         # dots: 0 = automatic
//   corners = [9, 6]           # chessboard: inner corners
#include <filesystem>
#include <string>

#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::calibration {

struct TargetFile {
  TargetSpec spec;
  std::string y_axis = "auto";  // dots: down, up or auto
};

// Throws tomorig::Error (bad_input) naming the file, the line or key, and what is expected.
TargetFile read_target_file(const std::filesystem::path& path);

}  // namespace tomorig::calibration
