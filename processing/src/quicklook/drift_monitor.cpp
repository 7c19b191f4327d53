// Drift alarm: volume self-calibration's disparity measurement over a window of recent sets
// (drift_monitor.h). The steps are self-calibration's own (calibration/self_calibration_*.cpp),
// used here without the correction.
#include "tomorig/processing/quicklook/drift_monitor.h"

#include <algorithm>
#include <deque>

#include <fmt/format.h>

#include "calibration/self_calibration_internal.h"
#include "tomorig/core/error.h"

namespace tomorig::quicklook {
namespace {

namespace selfcal = calibration::selfcal;

// A camera needs this many valid sub-volumes to be watched (as self-calibration needs to
// measure one).
constexpr int kMinSubvolumes = 4;

std::string name_of(const DriftOptions& options, std::size_t c) {
  return c < options.camera_names.size() ? options.camera_names[c] : fmt::format("camera {}", c);
}

void append(selfcal::Matches& to, const selfcal::Matches& from) {
  to.cameras = from.cameras;
  to.world.insert(to.world.end(), from.world.begin(), from.world.end());
  to.disparity.insert(to.disparity.end(), from.disparity.begin(), from.disparity.end());
  to.weight.insert(to.weight.end(), from.weight.begin(), from.weight.end());
  to.unique += from.unique;
}

}  // namespace

void DriftOptions::validate() const {
  if (subvolumes_x < 1 || subvolumes_y < 1 || subvolumes_z < 1 || subvolumes_x > 50 || subvolumes_y > 50 ||
      subvolumes_z > 50)
    throw bad_input(fmt::format("drift.subvolumes = {} x {} x {} is out of range: 1 to 50 each", subvolumes_x,
                                subvolumes_y, subvolumes_z));
  if (!(search_radius_px > 0 && search_radius_px <= 20))
    throw bad_input(fmt::format("drift.search_radius_px = {} is out of range: (0, 20] px", search_radius_px));
  if (window_sets < 1 || window_sets > 1000)
    throw bad_input(fmt::format("drift.window_sets = {} is out of range: 1 to 1000", window_sets));
  if (warmup_sets < 1)
    throw bad_input(fmt::format("drift.warmup_sets = {} must be >= 1", warmup_sets));
  if (min_matches_per_subvolume < 1)
    throw bad_input(fmt::format("drift.min_matches_per_subvolume = {} must be >= 1", min_matches_per_subvolume));
  if (!(warn_px > 0 && warn_px < search_radius_px))
    throw bad_input(fmt::format("drift.warn_px = {} must be > 0 and below the search radius {} px", warn_px,
                                search_radius_px));
  if (!(peak_threshold >= 0))
    throw bad_input(fmt::format("drift.peak_threshold = {} must be >= 0 (0: automatic)", peak_threshold));
}

struct DriftMonitor::Window {
  std::deque<selfcal::Matches> sets;  // newest last
};

DriftMonitor::DriftMonitor(std::vector<std::shared_ptr<const calibration::CameraModel>> models,
                           std::vector<calibration::ImageSize> sizes, const calibration::VolumeBounds& bounds,
                           const DriftOptions& options)
    : models_(std::move(models)), sizes_(std::move(sizes)), bounds_(bounds), options_(options),
      window_(std::make_unique<Window>()) {
  options_.validate();
  if (const std::string problem = bounds_.validate(); !problem.empty()) throw bad_input("drift monitor volume: " + problem);
  if (models_.size() < 3)
    throw bad_input(fmt::format("drift monitor: {} camera(s); triangulating particles to measure disparities needs at "
                                "least 3",
                                models_.size()));
  if (sizes_.size() != models_.size())
    throw bad_input(fmt::format("drift monitor: {} camera models but {} image sizes", models_.size(), sizes_.size()));
  for (std::size_t c = 0; c < models_.size(); ++c)
    if (!models_[c]) throw bad_input(fmt::format("drift monitor: {} has no camera model", name_of(options_, c)));
  reset();
}

DriftMonitor::~DriftMonitor() = default;
DriftMonitor::DriftMonitor(DriftMonitor&&) noexcept = default;
DriftMonitor& DriftMonitor::operator=(DriftMonitor&&) noexcept = default;

void DriftMonitor::reset() {
  window_->sets.clear();
  measure();
}

const DriftReport& DriftMonitor::add_set(std::span<const Image> images) {
  if (images.size() != models_.size())
    throw bad_input(fmt::format("drift monitor: {} images for {} cameras", images.size(), models_.size()));
  std::vector<std::vector<Vec2d>> peaks(images.size());
  for (std::size_t c = 0; c < images.size(); ++c) {
    const Image& im = images[c];
    if (im.width() != sizes_[c].width || im.height() != sizes_[c].height)
      throw bad_input(fmt::format("drift monitor: {}'s image is {} x {} but its calibration is for {} x {}",
                                  name_of(options_, c), im.width(), im.height(), sizes_[c].width, sizes_[c].height));
    peaks[c] = selfcal::detect_peaks(im, options_.peak_threshold);
  }
  return add_peaks(peaks);
}

const DriftReport& DriftMonitor::add_peaks(const std::vector<std::vector<Vec2d>>& peaks) {
  if (peaks.size() != models_.size())
    throw bad_input(fmt::format("drift monitor: peaks of {} cameras for {} cameras", peaks.size(), models_.size()));
  std::vector<selfcal::PeakIndex> index;
  for (std::size_t c = 0; c < peaks.size(); ++c) index.emplace_back(peaks[c], sizes_[c].width, sizes_[c].height);
  selfcal::ModelList models;
  for (const auto& m : models_) models.push_back(m.get());
  selfcal::Matches matches;
  selfcal::find_matches(models, index, bounds_, options_.search_radius_px, matches);
  matches.cameras = models_.size();
  window_->sets.push_back(std::move(matches));
  while (window_->sets.size() > static_cast<std::size_t>(options_.window_sets)) window_->sets.pop_front();
  measure();
  return report_;
}

void DriftMonitor::measure() {
  const std::size_t cameras = models_.size();
  selfcal::Matches pooled;
  pooled.cameras = cameras;
  for (const selfcal::Matches& m : window_->sets) append(pooled, m);

  const selfcal::SubvolumeGrid grid{bounds_, options_.subvolumes_x, options_.subvolumes_y, options_.subvolumes_z};
  calibration::SelfCalibrationOptions so;
  so.subvolumes_x = options_.subvolumes_x;
  so.subvolumes_y = options_.subvolumes_y;
  so.subvolumes_z = options_.subvolumes_z;
  so.min_matches_per_subvolume = options_.min_matches_per_subvolume;
  const selfcal::DisparityMaps maps = selfcal::measure_disparities(pooled, grid, options_.search_radius_px, so);
  selfcal::ModelList models;
  for (const auto& m : models_) models.push_back(m.get());
  // Against the calibration itself: the sparsest set of per-camera disparities that explains
  // the measurement, so a camera that moved carries its own shift.
  const selfcal::DisparityMaps drift = selfcal::gauge_corrections(models, models, maps, true);

  DriftReport& r = report_;
  r.sets = static_cast<int>(window_->sets.size());
  r.matches = pooled.size();
  r.cameras.assign(cameras, std::vector<SubvolumeDrift>(static_cast<std::size_t>(grid.count())));
  r.largest_px.assign(cameras, 0.0);
  r.valid_subvolumes.assign(cameras, 0);
  r.alarms.clear();
  r.flag = Flag::green;
  for (std::size_t c = 0; c < cameras; ++c) {
    for (int s = 0; s < grid.count(); ++s) {
      const selfcal::SubvolumeDisparity& d = drift[c][static_cast<std::size_t>(s)];
      SubvolumeDrift& out = r.cameras[c][static_cast<std::size_t>(s)];
      out.i = s % grid.nx;
      out.j = (s / grid.nx) % grid.ny;
      out.k = s / (grid.nx * grid.ny);
      out.centre = grid.centre(s);
      out.disparity = d.disparity;
      out.support = d.support;
      out.valid = d.valid;
      if (!out.valid) continue;
      ++r.valid_subvolumes[c];
      r.largest_px[c] = std::max(r.largest_px[c], out.magnitude());
      if (out.magnitude() > options_.warn_px && r.sets >= std::min(options_.warmup_sets, options_.window_sets)) {
        DriftAlarm alarm;
        alarm.camera = name_of(options_, c);
        alarm.camera_index = static_cast<int>(c);
        alarm.subvolume = out;
        alarm.message = fmt::format(
            "{} is {:.2f} px off its calibration in sub-volume ({}, {}, {}) around x {:.1f}, y {:.1f}, z {:.1f} mm "
            "({:.0f} particles over the last {} sets; warning above {} px): check the camera mount, and recalibrate "
            "(tomorig selfcal) if it stays",
            alarm.camera, out.magnitude(), out.i, out.j, out.k, out.centre.x, out.centre.y, out.centre.z, out.support,
            r.sets, options_.warn_px);
        r.alarms.push_back(std::move(alarm));
      }
    }
    if (r.valid_subvolumes[c] < kMinSubvolumes) r.flag = worst(r.flag, Flag::amber);
  }
  if (!r.alarms.empty()) r.flag = Flag::red;
}

}  // namespace tomorig::quicklook
