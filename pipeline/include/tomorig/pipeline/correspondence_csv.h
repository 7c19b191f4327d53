#pragma once
// Reading point correspondences made elsewhere (e.g. a target detected with another tool):
// a CSV file with a header and one row per calibration point,
//
//   camera,X,Y,Z,x,y[,plane]
//
// camera: integer index 0..N-1; X, Y, Z: world position in mm; x, y: image position in pixels
// (pixel convention of camera_model.h); plane: optional integer label, read and checked but
// not used (planes are told apart by Z). Columns may come in any order; blank lines and lines
// starting with '#' are skipped; a UTF-8 byte-order mark and CRLF line ends are accepted. Format: docs/calibration.md, "Command line".
#include <filesystem>
#include <vector>

#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::pipeline {

// The points of each camera: cameras[i] holds camera i's points, in file order.
struct CorrespondenceTable {
  std::vector<std::vector<calibration::PointCorrespondence>> cameras;
  // lines[i][k]: the file line of cameras[i][k] (read from a file; empty for detected points).
  std::vector<std::vector<int>> lines;
};

// Throws tomorig::Error (bad_input) naming the file, the line and the column and saying what is
// expected: a missing file, a bad header, a wrong field count, a field that is not a (finite)
// number, a negative camera index, or a camera index with no points below the highest one.
CorrespondenceTable read_correspondence_csv(const std::filesystem::path& path);

// Writes `table` in the same format (camera,X,Y,Z,x,y, numbers that read back exactly), e.g.
// points detected by `tomorig calibrate --images` for use elsewhere. Throws bad_input naming
// the file if it cannot be written.
void write_correspondence_csv(const std::filesystem::path& path, const CorrespondenceTable& table);

}  // namespace tomorig::pipeline
