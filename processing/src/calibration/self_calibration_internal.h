#pragma once
// The steps of volume self-calibration (self_calibration.h), one file each:
//   self_calibration_match.cpp      triangulation of candidate particles
//   self_calibration_disparity.cpp  sub-volume disparities
//   self_calibration_correct.cpp    gauge, smoothing field and model refit
//   self_calibration.cpp            the iteration and the report
#include <cstddef>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "selfcal_peaks.h"
#include "tomorig/processing/calibration/self_calibration.h"

namespace tomorig::calibration::selfcal {

using ModelList = std::vector<const CameraModel*>;

// Candidate 3-D particles of one pass, all snapshots together, ghosts included.
struct Matches {
  std::size_t cameras = 0;
  std::vector<Vec3d> world;
  std::vector<Vec2d> disparity;  // `cameras` per match: projected 3-D point minus detected peak
  std::vector<float> weight;     // 1 / (candidates of the same reference peak)
  std::size_t unique = 0;        // reference peaks with exactly one candidate

  std::size_t size() const { return world.size(); }
  const Vec2d& disparity_of(std::size_t match, std::size_t camera) const { return disparity[match * cameras + camera]; }
};

// The point closest (least squares) to all rays.
Vec3d closest_point(std::span<const Ray> rays);

// Appends to `out` the candidate particles of one snapshot: every reference-camera peak is
// searched along its line of sight within `radius_px` in the other cameras; candidates whose
// least-squares point reprojects within `radius_px` of a peak in every camera are kept.
void find_matches(const ModelList& models, const std::vector<PeakIndex>& peaks, const VolumeBounds& bounds,
                  double radius_px, Matches& out);

struct SubvolumeGrid {
  VolumeBounds bounds;
  int nx = 1, ny = 1, nz = 1;

  int count() const { return nx * ny * nz; }
  int index_of(const Vec3d& world) const;  // -1 outside the bounds
  Vec3d centre(int index) const;
  int layer(int index) const { return index / (nx * ny); }  // z index
  double layer_z(int layer) const;
};

struct SubvolumeDisparity {
  Vec2d disparity;     // most probable disparity, px
  double support = 0;  // weighted matches near the disparity peak
  Vec3d centroid;      // mean world position of those matches
  bool valid = false;  // support >= options.min_matches_per_subvolume
};
using DisparityMaps = std::vector<std::vector<SubvolumeDisparity>>;  // [camera][sub-volume]

DisparityMaps measure_disparities(const Matches& matches, const SubvolumeGrid& grid, double radius_px,
                                  const SelfCalibrationOptions& options);

// Figures of one camera's maps, per Table 5.4 (all sub-volumes, z-min and z-max layers).
CameraDisparity summarise(const CameraModel& model, const std::vector<SubvolumeDisparity>& maps,
                          const SubvolumeGrid& grid);

// The correction each camera needs per sub-volume (what its projections must move by, px,
// with the sign of a disparity), in the gauge the options ask for. `initial`: the models the
// self-calibration started from, which the sparse gauge measures the total correction against.
DisparityMaps gauge_corrections(const ModelList& initial, const ModelList& models, const DisparityMaps& maps,
                                bool sparse_gauge);

// The model of the same type refitted to a lattice over `bounds`: world point X paired with
// model.project(X) + offset(X, model.project(X)).
std::unique_ptr<CameraModel> refit_with_offsets(const CameraModel& model, ImageSize image_size,
                                                const VolumeBounds& bounds,
                                                const std::function<Vec2d(const Vec3d&, const Vec2d&)>& offset,
                                                const std::string& camera_name, FitReport& report);

// A smooth field through one camera's sub-volume corrections (quadratic in x, y, linear in z
// and its cross terms; linear if there are too few sub-volumes). Throws bad_input naming the
// camera if fewer than 4 sub-volumes are valid.
class CorrectionField {
 public:
  CorrectionField(const std::vector<SubvolumeDisparity>& corrections, const VolumeBounds& bounds,
                  const std::string& camera_name);
  Vec2d at(const Vec3d& world) const;

 private:
  std::size_t terms_ = 0;
  Vec3d centre_, half_size_;
  std::vector<double> cx_, cy_;  // coefficients per basis term
  void basis(const Vec3d& world, double* out) const;
};

}  // namespace tomorig::calibration::selfcal
