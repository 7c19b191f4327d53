#pragma once
// The z of each target point from a side file (`tomorig calibrate --target-z Z.csv`, issue 18;
// docs/calibration.md, "Point depths from a side file"): for a plate whose dots do not all lie
// at one depth (a machined 3-D target, a two-level plate measured dot by dot), a CSV with the
// header X,Y,Z and one row per target point:
//
//   X,Y,Z          # mm: the point's world x, y (as --points-out writes them) and its z
//   0,0,0          #     relative to the plate's position (the plane z of the image)
//   1,1,-0.512
//
// Columns in any order; blank lines and lines starting with '#' are skipped; a UTF-8
// byte-order mark and CRLF line ends are accepted. Rows for points not seen are allowed.
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "tomorig/processing/calibration/fit_types.h"

namespace tomorig::calibration {

struct TargetDepths {
  std::string file;
  // Keyed by X, Y in units of 1e-4 mm (rounded): the point's z relative to the plate, mm.
  std::map<std::pair<long long, long long>, double> z_mm;
};

// Throws tomorig::Error (bad_input) naming the file and the line: a missing file, a header
// without X, Y and Z (or with other columns), a wrong field count, a field that is not a finite
// number, a point listed twice, no point at all.
TargetDepths read_target_depths(const std::filesystem::path& path);

// Each point's world z becomes its z (the plane z of its image) plus the file's Z at its
// world x, y. Throws bad_input naming the camera, the plane, the point and the file when a
// point is not in the file (the file and the detected target do not match).
void apply_target_depths(std::span<std::vector<PointCorrespondence>> cameras, const TargetDepths& depths);

}  // namespace tomorig::calibration
