#pragma once
// Target images for `tomorig calibrate`: where they are, which camera and plane z each shows,
// and the point correspondences detected in them. Layouts (docs/calibration.md, "Target
// images"):
//   --images DIR       DIR/<camera folder>/<z>mm<anything>.tif, a camera folder being any
//                      sub-folder whose name ends in a number (cam0, cam1, ...), cameras taken
//                      in the order of that number; the fluidimage layout
//                      calibration/cam0/-3mm_cam0.tif is of this form.
//   --image-list CSV   a header camera,z,file and one row per image (file relative to the CSV).
//   --session S.h5     one set per plane, exposure A of each camera is its target image; plane
//                      z from the truth (`tomorig simulate --case calib-thesis`: nominal z of
//                      each set in flow_parameters "planes") or from --z-list (one z per set).
#include <filesystem>
#include <string>
#include <vector>

#include "tomorig/pipeline/correspondence_csv.h"
#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/calibration/target_detection.h"

namespace tomorig::pipeline {

struct TargetImage {
  int camera = 0;
  double z_mm = 0;
  std::filesystem::path file;  // an image file, or the session file when session_set >= 0
  long long session_set = -1;  // >= 0: exposure A of this camera in this set of `file`
};

struct TargetImageSet {
  std::vector<TargetImage> images;      // sorted by camera, then z
  std::vector<std::string> camera_names;  // per camera: its folder, session camera id or "camera i"
};

// Throws bad_input naming the folder or file: no camera folders, a folder without "<z>mm"
// images, a file name whose z cannot be read, two images of one camera at the same z.
TargetImageSet find_target_images(const std::filesystem::path& dir);
TargetImageSet read_image_list(const std::filesystem::path& csv);
// Throws bad_input if the session cannot be opened, or if it has no plane z (no truth
// "planes" and `z_list` empty: the message says to give --z-list), or `z_list` does not have
// one z per set. Only the nominal z of the truth is used, never its true offsets.
TargetImageSet read_session_targets(const std::filesystem::path& session, const std::vector<double>& z_list);

// The plane z of a file name "<z>mm...", e.g. "-3mm_cam0.tif" -> -3, "1.5mm.tif" -> 1.5.
bool parse_plane_z(const std::string& file_name, double& z_mm);

struct DetectedTargets {
  CorrespondenceTable table;                       // per camera, all planes
  std::vector<calibration::ImageSize> image_sizes;  // per camera
  std::vector<std::string> warnings;               // from detection, prefixed by camera and plane
  // Per dot-grid image: where the origin was placed and how ("camera 0, plane z = 1 mm: origin
  // (filled square) at (201.3, 160.2) px, +x towards (28.1, 3.0) px, set by the triangle").
  std::vector<std::string> origins;
};

// Where detect_targets draws what it found (calibration::draw_detection_overlay), one PNG per
// image named cam<camera>_<z>mm.png; empty: no overlays. Existing files are refused (before any
// detection) unless `overwrite`.
struct OverlayOutput {
  std::filesystem::path dir;
  bool overwrite = false;
};

// Detects the target in every image. Throws bad_input naming the camera, the plane and the
// file when an image cannot be read, differs in size from its camera's other images, shows no
// target, or gives fewer than `min_points_per_plane` identified points.
// For `--y-axis auto` on a dot grid (detected with y down): flips world y on every camera if
// that makes (x, y, z) right-handed. The image of the target grows as it nears the camera, so
// the way its scale changes with z tells whether z points towards the cameras; then y must
// point up the image (x being to the right). Returns "down" or "up". Throws bad_input if the
// cameras disagree or the scale does not change measurably with z (a telecentric view: give
// --y-axis down or up).
std::string orient_y_axis(DetectedTargets& detected);

DetectedTargets detect_targets(const TargetImageSet& set, const calibration::TargetSpec& spec,
                               int min_points_per_plane, const OverlayOutput& overlay = {});

}  // namespace tomorig::pipeline
