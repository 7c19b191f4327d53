#pragma once
// Drift alarm (issue 16, item 4): the particle disparity of each camera against its calibration,
// per sub-volume, accumulated over the most recent sets; a warning names the camera and the
// sub-volume where it passes warn_px (0.3 px: twice the 0.1-0.2 px the thesis, after Wieneke,
// asks of a calibration for tomographic reconstruction, Sect. 2.2).
//
// It is volume self-calibration's disparity measurement (calibration/self_calibration.h) run
// online, without the correction: peaks per camera, triangulated candidate particles within a
// search radius, the most probable disparity per camera and sub-volume from a disparity map
// over the sets in the window, then the sparse gauge, which gives a moved camera its whole
// disparity instead of spreading it over all cameras as least squares would.
//
// A stage keeps one DriftMonitor for the rig (it holds the matches of the recent sets) and calls
// add_set() with the images of all cameras of one exposure, every set or every few sets; the
// returned report is valid until the next call. Allocation happens per call (peaks, matches):
// this is the slow path of the quick-look, seconds of budget rather than milliseconds.
#include <cmath>
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "tomorig/core/geometry.h"
#include "tomorig/core/image.h"
#include "tomorig/processing/calibration/camera_model.h"
#include "tomorig/processing/calibration/fit_types.h"
#include "tomorig/processing/calibration/self_calibration.h"
#include "tomorig/processing/quicklook/targets.h"

namespace tomorig::quicklook {

struct DriftOptions {
  // Sub-volumes along x, y, z, as volume self-calibration's.
  int subvolumes_x = 5, subvolumes_y = 5, subvolumes_z = 3;
  // Search radius of the triangulation, px: a drift larger than this loses the matches
  // (reported as too few matched particles) rather than growing the disparity.
  double search_radius_px = 1.0;
  int window_sets = 10;                 // sets whose matches are pooled
  int warmup_sets = 3;                  // no alarm before the window holds this many (or all) sets
  int min_matches_per_subvolume = 10;   // matches near the disparity peak for a sub-volume to count
  double warn_px = 0.3;                 // a sub-volume disparity above this is an alarm
  double peak_threshold = 0;            // particle peaks below this are ignored (counts; 0: automatic)
  std::vector<std::string> camera_names;  // empty: "camera 0", "camera 1", ...

  // Throws tomorig::Error (bad_input) naming the field, its value and what is allowed.
  void validate() const;
};

struct SubvolumeDrift {
  int i = 0, j = 0, k = 0;  // sub-volume index along x, y, z
  Vec3d centre;             // world mm
  Vec2d disparity;          // px, projected particle minus detected peak, sparse gauge
  double support = 0;       // matches near the disparity peak
  bool valid = false;       // support >= min_matches_per_subvolume
  double magnitude() const { return std::hypot(disparity.x, disparity.y); }
};

struct DriftAlarm {
  std::string camera;
  int camera_index = 0;
  SubvolumeDrift subvolume;
  std::string message;  // e.g. "cam1 is 0.48 px off its calibration in sub-volume (2, 3, 1) ..."
};

struct DriftReport {
  int sets = 0;                 // sets pooled in the window
  std::size_t matches = 0;      // candidate particles in the window (ghosts included)
  std::vector<std::vector<SubvolumeDrift>> cameras;  // [camera][sub-volume], x fastest
  std::vector<double> largest_px;  // per camera: the largest valid sub-volume disparity
  std::vector<int> valid_subvolumes;  // per camera
  std::vector<DriftAlarm> alarms;  // none while warming up (fewer than warmup_sets sets)
  // red: an alarm; amber: a camera with fewer than 4 valid sub-volumes (cannot be watched:
  // too few particles, or a drift beyond the search radius); green otherwise.
  Flag flag = Flag::amber;
};

class DriftMonitor {
 public:
  // `models`: the rig's calibration, one per camera; `sizes`: their image sizes; `bounds`: the
  // measurement volume. Throws tomorig::Error (bad_input) for invalid options or bounds, fewer
  // than 3 cameras, or mismatched lists.
  DriftMonitor(std::vector<std::shared_ptr<const calibration::CameraModel>> models,
               std::vector<calibration::ImageSize> sizes, const calibration::VolumeBounds& bounds,
               const DriftOptions& options = {});
  ~DriftMonitor();
  DriftMonitor(DriftMonitor&&) noexcept;
  DriftMonitor& operator=(DriftMonitor&&) noexcept;

  // Adds one exposure of a set (one image per camera, in camera order) and re-measures over
  // the window. Throws tomorig::Error (bad_input) for a wrong number or size of images.
  const DriftReport& add_set(std::span<const Image> images);
  // The same with particle peaks (px, per camera) found elsewhere, e.g. by the preview.
  const DriftReport& add_peaks(const std::vector<std::vector<Vec2d>>& peaks);
  const DriftReport& report() const { return report_; }
  // Forgets the window, e.g. after a recalibration.
  void reset();

 private:
  struct Window;
  void measure();

  std::vector<std::shared_ptr<const calibration::CameraModel>> models_;
  std::vector<calibration::ImageSize> sizes_;
  calibration::VolumeBounds bounds_;
  DriftOptions options_;
  std::unique_ptr<Window> window_;
  DriftReport report_;
};

}  // namespace tomorig::quicklook
