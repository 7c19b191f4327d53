#include "tomorig/processing/particles/droplets.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/core.h>

#include "tomorig/core/error.h"
#include "tomorig/processing/particles/extraction.h"

namespace tomorig::particles {

void DropletDetectionOptions::validate() const {
  if (!(relative_peak_threshold >= 0 && relative_peak_threshold < 1))
    throw bad_input(fmt::format("droplet detection: relative_peak_threshold must be in [0, 1), got {}",
                                relative_peak_threshold));
  if (max_radius_voxel < 1 || max_radius_voxel > 32)
    throw bad_input(fmt::format("droplet detection: max_radius_voxel must be 1 to 32, got {}", max_radius_voxel));
}

std::vector<DetectedDroplet> detect_droplets(const DenseVolume& volume, const DropletDetectionOptions& options) {
  options.validate();
  ExtractionOptions extraction;
  extraction.relative_peak_threshold = options.relative_peak_threshold;
  extraction.max_radius_voxel = options.max_radius_voxel;
  extraction.threads = options.threads;
  const ExtractionReport report = extract_particles(volume, extraction);
  const VoxelGrid& g = volume.grid;
  std::vector<DetectedDroplet> out;
  out.reserve(report.particles.size());
  for (const Particle& p : report.particles) {
    const std::uint32_t n = p.peak_index;
    const int pi = static_cast<int>(n % static_cast<std::uint32_t>(g.nx));
    const int pj = static_cast<int>((n / static_cast<std::uint32_t>(g.nx)) % static_cast<std::uint32_t>(g.ny));
    const int pk = static_cast<int>(n / (static_cast<std::uint32_t>(g.nx) * static_cast<std::uint32_t>(g.ny)));
    const float half = 0.5f * p.peak;
    const int r = options.max_radius_voxel;
    int area = 0;
    for (int j = std::max(0, pj - r); j <= std::min(g.ny - 1, pj + r); ++j)
      for (int i = std::max(0, pi - r); i <= std::min(g.nx - 1, pi + r); ++i)
        if (volume.at(i, j, pk) >= half) ++area;
    DetectedDroplet d;
    d.world = p.world;
    d.peak = p.peak;
    d.integrated = p.integrated;
    d.d_eq_mm = 2.0 * std::sqrt(area / std::numbers::pi) * g.voxel_size;
    out.push_back(d);
  }
  return out;
}

}  // namespace tomorig::particles
