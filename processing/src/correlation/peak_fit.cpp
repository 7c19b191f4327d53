#include "tomorig/processing/correlation/peak_fit.h"

#include <algorithm>
#include <cmath>

namespace tomorig::piv {

PeakFit1d fit_peak_1d(double left, double centre, double right, bool has_left, bool has_right) {
  if (!has_left || !has_right) {
    // At the edge of the plane one neighbour is missing (it would wrap around the periodic
    // correlation): the centroid of the peak and its one neighbour is the best we can do.
    const double neighbour = has_left ? left : (has_right ? right : 0.0);
    const double sign = has_left ? -1.0 : 1.0;
    if (!(has_left || has_right) || neighbour <= 0.0 || centre <= 0.0) return {0.0, PeakFitMethod::centroid};
    return {std::clamp(sign * neighbour / (neighbour + centre), -0.5, 0.5), PeakFitMethod::centroid};
  }
  if (left > 0.0 && centre > 0.0 && right > 0.0) {
    const double ll = std::log(left), lc = std::log(centre), lr = std::log(right);
    const double denominator = 2.0 * ll - 4.0 * lc + 2.0 * lr;
    if (denominator < 0.0) return {std::clamp((ll - lr) / denominator, -0.5, 0.5), PeakFitMethod::gaussian};
  }
  // log() is undefined for values <= 0 (a normalised correlation goes negative): a parabola.
  const double denominator = 2.0 * left - 4.0 * centre + 2.0 * right;
  if (denominator < 0.0) return {std::clamp((left - right) / denominator, -0.5, 0.5), PeakFitMethod::parabolic};
  return {0.0, PeakFitMethod::none};
}

}  // namespace tomorig::piv
