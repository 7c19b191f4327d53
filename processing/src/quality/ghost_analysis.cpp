#include "tomorig/processing/quality/ghost_analysis.h"

#include <limits>

namespace tomorig::quality {

GhostAnalysis classify_blobs(std::span<const particles::Particle> blobs, const EllipsoidMask& mask) {
  GhostAnalysis g;
  double true_sum = 0.0, ghost_sum = 0.0;
  for (const particles::Particle& b : blobs) {
    if (mask.contains(b.peak_index)) {
      ++g.true_blobs;
      true_sum += b.mean_intensity();
    } else {
      ++g.ghost_blobs;
      ghost_sum += b.mean_intensity();
    }
  }
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (g.true_blobs > 0) g.true_mean_intensity = true_sum / g.true_blobs;
  if (g.ghost_blobs > 0) g.ghost_mean_intensity = ghost_sum / g.ghost_blobs;
  g.ghost_true_count_ratio =
      g.ghost_blobs == 0 ? 0.0 : (g.true_blobs == 0 ? kInf : static_cast<double>(g.ghost_blobs) / g.true_blobs);
  g.true_ghost_intensity_ratio =
      g.true_blobs == 0 ? 0.0
                        : (g.ghost_blobs == 0 || g.ghost_mean_intensity <= 0.0 ? kInf
                                                                              : g.true_mean_intensity / g.ghost_mean_intensity);
  return g;
}

}  // namespace tomorig::quality
