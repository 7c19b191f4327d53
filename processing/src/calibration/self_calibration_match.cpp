// Triangulation of candidate particles for volume self-calibration (Wieneke 2008, Sect. 2):
// epipolar search from a reference camera, verification in every other camera, and the
// least-squares 3-D point from all lines of sight.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "self_calibration_internal.h"

namespace tomorig::calibration::selfcal {
namespace {

constexpr std::size_t kReference = 0;
constexpr int kEpipolarSamples = 9;  // polyline vertices: the image of a line of sight may bend

double distance_to_segment(const Vec2d& p, const Vec2d& a, const Vec2d& b) {
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double length2 = ex * ex + ey * ey;
  double t = length2 > 0 ? ((p.x - a.x) * ex + (p.y - a.y) * ey) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p.x - (a.x + t * ex), p.y - (a.y + t * ey));
}

bool inside(const VolumeBounds& b, const Vec3d& p) {
  return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y && p.z >= b.min.z && p.z <= b.max.z;
}

// Depths sampled along a line of sight: the volume's z range and 5 % more on either side,
// so a particle at the boundary is found even through a slightly wrong model.
std::vector<double> sample_depths(const VolumeBounds& bounds) {
  const double margin = 0.05 * (bounds.max.z - bounds.min.z);
  std::vector<double> z(kEpipolarSamples);
  for (int i = 0; i < kEpipolarSamples; ++i)
    z[static_cast<std::size_t>(i)] =
        bounds.min.z - margin + (bounds.max.z - bounds.min.z + 2 * margin) * i / (kEpipolarSamples - 1.0);
  return z;
}

// The partner of the reference camera for the epipolar search: the one whose image of the
// reference camera's central line of sight is shortest, so the search meets fewest peaks.
std::size_t partner_camera(const ModelList& models, const VolumeBounds& bounds) {
  const Vec3d centre = (bounds.min + bounds.max) * 0.5;
  const Vec2d pixel = models[kReference]->project(centre);
  std::size_t best = 1;
  double best_length = std::numeric_limits<double>::infinity();
  for (std::size_t c = 1; c < models.size(); ++c) {
    const Vec2d a = models[c]->project(models[kReference]->back_project(pixel, bounds.min.z));
    const Vec2d b = models[c]->project(models[kReference]->back_project(pixel, bounds.max.z));
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    if (length < best_length) {
      best_length = length;
      best = c;
    }
  }
  return best;
}

}  // namespace

Vec3d closest_point(std::span<const Ray> rays) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const Ray& r : rays) {
    const Eigen::Vector3d d(r.direction.x, r.direction.y, r.direction.z);
    const Eigen::Vector3d o(r.origin.x, r.origin.y, r.origin.z);
    const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - d * d.transpose() / d.squaredNorm();
    a += p;
    b += p * o;
  }
  const Eigen::Vector3d x = a.ldlt().solve(b);
  return {x.x(), x.y(), x.z()};
}

void find_matches(const ModelList& models, const std::vector<PeakIndex>& peaks, const VolumeBounds& bounds,
                  double radius_px, Matches& out) {
  const std::size_t cameras = models.size();
  out.cameras = cameras;
  const std::size_t partner = partner_camera(models, bounds);
  const std::vector<double> depths = sample_depths(bounds);
  // Other cameras check the two-ray point, whose error adds those of two peaks: search them a
  // little wider; the final test on the least-squares point uses radius_px.
  const double verify_radius = 1.5 * radius_px;

  std::vector<Vec2d> polyline(depths.size());
  std::vector<Ray> rays(cameras);
  std::vector<Vec2d> detected(cameras);
  std::vector<Vec2d> disparity(cameras);
  std::vector<int> candidates;
  // Candidates of the current reference peak, appended to `out` once they are all known.
  std::vector<Vec3d> found_world;
  std::vector<Vec2d> found_disparity;

  for (const Vec2d& p : peaks[kReference].peaks()) {
    const Ray ray_a = models[kReference]->line_of_sight(p);
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    for (std::size_t i = 0; i < depths.size(); ++i) {
      polyline[i] = models[partner]->project(models[kReference]->back_project(p, depths[i]));
      x0 = std::min(x0, polyline[i].x), x1 = std::max(x1, polyline[i].x);
      y0 = std::min(y0, polyline[i].y), y1 = std::max(y1, polyline[i].y);
    }
    candidates.clear();
    peaks[partner].for_each_in_box(x0 - radius_px, y0 - radius_px, x1 + radius_px, y1 + radius_px, [&](int n) {
      const Vec2d& q = peaks[partner].peaks()[static_cast<std::size_t>(n)];
      for (std::size_t i = 0; i + 1 < polyline.size(); ++i)
        if (distance_to_segment(q, polyline[i], polyline[i + 1]) <= radius_px) {
          candidates.push_back(n);
          return;
        }
    });
    found_world.clear();
    found_disparity.clear();
    for (const int n : candidates) {
      detected[kReference] = p;
      detected[partner] = peaks[partner].peaks()[static_cast<std::size_t>(n)];
      rays[kReference] = ray_a;
      rays[partner] = models[partner]->line_of_sight(detected[partner]);
      const std::array<Ray, 2> pair{rays[kReference], rays[partner]};
      const Vec3d two_ray = closest_point(pair);
      bool seen_by_all = true;
      for (std::size_t c = 0; c < cameras && seen_by_all; ++c) {
        if (c == kReference || c == partner) continue;
        const int m = peaks[c].nearest(models[c]->project(two_ray), verify_radius);
        if (m < 0) {
          seen_by_all = false;
          break;
        }
        detected[c] = peaks[c].peaks()[static_cast<std::size_t>(m)];
        rays[c] = models[c]->line_of_sight(detected[c]);
      }
      if (!seen_by_all) continue;
      const Vec3d world = closest_point(rays);
      if (!inside(bounds, world)) continue;
      bool consistent = true;
      for (std::size_t c = 0; c < cameras && consistent; ++c) {
        const Vec2d projected = models[c]->project(world);
        disparity[c] = {projected.x - detected[c].x, projected.y - detected[c].y};
        consistent = std::hypot(disparity[c].x, disparity[c].y) <= radius_px;
      }
      if (!consistent) continue;
      found_world.push_back(world);
      found_disparity.insert(found_disparity.end(), disparity.begin(), disparity.end());
    }
    if (found_world.empty()) continue;
    if (found_world.size() == 1) ++out.unique;
    const float weight = 1.0f / static_cast<float>(found_world.size());
    out.world.insert(out.world.end(), found_world.begin(), found_world.end());
    out.disparity.insert(out.disparity.end(), found_disparity.begin(), found_disparity.end());
    out.weight.insert(out.weight.end(), found_world.size(), weight);
  }
}

}  // namespace tomorig::calibration::selfcal
